#include "trajroi/sim/path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace trajroi::sim {

double Path::Piece::length_m() const noexcept {
  return segment.kind == PathSegment::Kind::kLine ? segment.length_m : segment.radius_m * std::abs(segment.turn_rad);
}

Path::Path(const PathSpec& spec) {
  Eigen::Vector2d position = spec.start_m;
  double heading = spec.heading_rad;
  for (const PathSegment& segment : spec.segments) {
    Piece piece{length_m_, position, heading, segment};
    pieces_.push_back(piece);
    length_m_ += piece.length_m();
    const PathPose end = at(length_m_);
    position = end.position_m;
    heading = end.heading_rad;
  }
}

PathPose Path::at(double s_m) const noexcept {
  s_m = std::clamp(s_m, 0.0, length_m_);
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s_m,
                             [](double s, const Piece& piece) { return s < piece.s0_m; });
  const Piece& p = it == pieces_.begin() ? *it : *std::prev(it);
  const double u = std::min(s_m - p.s0_m, p.length_m());
  const double c0 = std::cos(p.heading_rad);
  const double s0 = std::sin(p.heading_rad);
  if (p.segment.kind == PathSegment::Kind::kLine) {
    return {p.start_m + u * Eigen::Vector2d(c0, s0), p.heading_rad, 0.0};
  }
  const double kappa = std::copysign(1.0 / p.segment.radius_m, p.segment.turn_rad);
  const double heading = p.heading_rad + kappa * u;
  const Eigen::Vector2d offset((std::sin(heading) - s0) / kappa, (c0 - std::cos(heading)) / kappa);
  return {p.start_m + offset, heading, kappa};
}

std::vector<Eigen::Vector2d> Path::polyline(double max_chord_m) const {
  std::vector<Eigen::Vector2d> points{at(0.0).position_m};
  for (const Piece& p : pieces_) {
    const double length = p.length_m();
    const int steps =
        p.segment.kind == PathSegment::Kind::kLine ? 1 : std::max(1, static_cast<int>(std::ceil(length / max_chord_m)));
    for (int k = 1; k <= steps; ++k)
      points.push_back(at(p.s0_m + length * k / steps).position_m);
  }
  return points;
}

std::string Path::trajectory_csv(const std::string& comment) const {
  std::string text = "# " + comment + "\n# x_m,y_m (global frame: ENU about the scenario origin)\n";
  char line[64];
  for (const Eigen::Vector2d& p : polyline()) {
    std::snprintf(line, sizeof line, "%.6f,%.6f\n", p.x(), p.y());
    text += line;
  }
  return text;
}

std::int64_t Motion::duration_ns() const noexcept {
  const double seconds = robot_.wait_before_s + path_.length_m() / robot_.speed_mps + robot_.wait_after_s;
  return static_cast<std::int64_t>(std::ceil(seconds * 1e9));
}

RobotState Motion::at(std::int64_t t_ns) const noexcept {
  const double drive_s = static_cast<double>(t_ns) * 1e-9 - robot_.wait_before_s;
  const double s = std::clamp(drive_s * robot_.speed_mps, 0.0, path_.length_m());
  const bool moving = drive_s > 0.0 && s < path_.length_m();
  const PathPose p = path_.at(s);
  const double speed = moving ? robot_.speed_mps : 0.0;
  return {p.position_m, p.heading_rad, speed, speed * p.curvature};
}

}  // namespace trajroi::sim
