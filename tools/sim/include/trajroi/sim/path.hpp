#pragma once

// The robot's path as exact geometry (lines and circular arcs), the robot's motion along it
// at constant speed, and the polyline written as the trajectory file.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "trajroi/sim/scenario.hpp"

namespace trajroi::sim {

struct PathPose {
  Eigen::Vector2d position_m;
  double heading_rad;  // counter-clockwise from +x
  double curvature;    // 1/m, positive turning left
};

class Path {
 public:
  explicit Path(const PathSpec& spec);
  [[nodiscard]] double length_m() const noexcept { return length_m_; }
  // The pose at arc length s (clamped to [0, length]).
  [[nodiscard]] PathPose at(double s_m) const noexcept;
  // Waypoints: every segment end, and along arcs chords of at most `max_chord_m` (their
  // sagitta c²/8R stays below a millimetre for c = 0.1 m and R ≥ 1.25 m).
  [[nodiscard]] std::vector<Eigen::Vector2d> polyline(double max_chord_m = 0.1) const;
  // The polyline as trajectory CSV text (`x,y` per line, µm resolution, a comment header).
  [[nodiscard]] std::string trajectory_csv(const std::string& comment) const;

 private:
  struct Piece {
    double s0_m;
    Eigen::Vector2d start_m;
    double heading_rad;
    PathSegment segment;
    [[nodiscard]] double length_m() const noexcept;
  };
  std::vector<Piece> pieces_;
  double length_m_ = 0.0;
};

// The robot at one instant: planar pose on the ground, speed and yaw rate.
struct RobotState {
  Eigen::Vector2d position_m;
  double yaw_rad;
  double speed_mps;
  double yaw_rate_rps;
};

// Stands still for `wait_before_s`, drives the path at `speed_mps`, stands still for
// `wait_after_s`. Time in ns after the first firing.
class Motion {
 public:
  Motion(const Path& path, const RobotSpec& robot) : path_(path), robot_(robot) {}
  [[nodiscard]] RobotState at(std::int64_t t_ns) const noexcept;
  [[nodiscard]] std::int64_t duration_ns() const noexcept;

 private:
  const Path& path_;
  RobotSpec robot_;
};

}  // namespace trajroi::sim
