#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace trajroi::roi {

enum class TrajectoryErrc {
  kTooFewPoints,    // fewer than two distinct waypoints (after removing consecutive duplicates)
  kNonFinitePoint,  // a waypoint coordinate is NaN or infinite
  kTooManyPoints,   // more waypoints than kMaxWaypoints
  kParse,           // text that is not a waypoint line
};

[[nodiscard]] std::string_view to_string(TrajectoryErrc code) noexcept;

// Thrown when a trajectory cannot be built. Construction happens at start-up or when a new
// trajectory arrives (a rare event): callers that must not stop catch it and count code().
class TrajectoryError : public std::invalid_argument {
 public:
  TrajectoryError(TrajectoryErrc code, const std::string& message) : std::invalid_argument(message), code_(code) {}
  [[nodiscard]] TrajectoryErrc code() const noexcept { return code_; }

 private:
  TrajectoryErrc code_;
};

// Closest point of a trajectory to a query position.
struct Projection {
  double s_m;             // arc length of the closest point
  double distance_m;      // distance from the query to it
  Eigen::Vector2d point;  // the closest point itself (global frame)
};

// The robot's target path: a polyline of global-frame XY waypoints (metres), parametrised by
// arc length s from its first waypoint.
//
// Invariants (checked on construction): every waypoint is finite; consecutive duplicates are
// removed; at least two distinct waypoints remain, so every segment has positive length.
class Trajectory {
 public:
  static constexpr std::size_t kMaxWaypoints = 1'000'000;

  explicit Trajectory(std::vector<Eigen::Vector2d> waypoints);  // throws TrajectoryError

  [[nodiscard]] const std::vector<Eigen::Vector2d>& waypoints() const noexcept { return points_; }
  [[nodiscard]] std::size_t segment_count() const noexcept { return points_.size() - 1; }
  [[nodiscard]] double length_m() const noexcept { return cum_s_.back(); }
  // Arc length at waypoint i.
  [[nodiscard]] double s_at_waypoint(std::size_t i) const noexcept { return cum_s_[i]; }

  // The segment holding arc length s: the i with s_at_waypoint(i) <= s < s_at_waypoint(i+1);
  // s is clamped to [0, length], and s = length gives the last segment.
  [[nodiscard]] std::size_t segment_at(double s_m) const noexcept;
  // P(s) = w_i + u_i · (s − s_i), with u_i the unit direction of segment i (s clamped).
  [[nodiscard]] Eigen::Vector2d point_at(double s_m) const noexcept;
  // Heading of the segment holding s, counter-clockwise from +x, in (−π, π].
  [[nodiscard]] double heading_at(double s_m) const noexcept;

  // Closest point over the whole polyline (ties: the smallest s).
  [[nodiscard]] Projection project(const Eigen::Vector2d& position) const noexcept;
  // Closest point with s restricted to [s_hint, s_hint + max_advance]: progress never goes
  // backwards, and a path that comes back near itself (hairpin, loop, crossing) cannot make
  // the projection jump to a later or earlier pass.
  [[nodiscard]] Projection project(const Eigen::Vector2d& position, double s_hint_m,
                                   double max_advance_m) const noexcept;

 private:
  [[nodiscard]] Projection project_range(const Eigen::Vector2d& position, double s_lo, double s_hi) const noexcept;

  std::vector<Eigen::Vector2d> points_;
  std::vector<Eigen::Vector2d> direction_;  // unit vector of each segment
  std::vector<double> cum_s_;               // arc length at each waypoint (metres)
  std::vector<double> heading_rad_;         // heading of each segment
};

// Parses a trajectory from CSV text: one `x,y` waypoint per line (metres, global frame),
// blank lines and `#` comments ignored, surrounding spaces allowed. `source_name` (usually
// the file path) starts every error message, followed by the line number:
// "traj.csv:7: expected 'x,y', got 'abc'".
[[nodiscard]] Trajectory parse_trajectory_csv(std::string_view text, std::string_view source_name);

}  // namespace trajroi::roi
