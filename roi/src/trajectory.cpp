#include "trajroi/roi/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "trajroi/roi/text.hpp"

namespace trajroi::roi {

std::string_view to_string(TrajectoryErrc code) noexcept {
  switch (code) {
    case TrajectoryErrc::kTooFewPoints:
      return "too_few_points";
    case TrajectoryErrc::kNonFinitePoint:
      return "non_finite_point";
    case TrajectoryErrc::kTooManyPoints:
      return "too_many_points";
    case TrajectoryErrc::kParse:
      return "parse";
  }
  return "unknown";
}

Trajectory::Trajectory(std::vector<Eigen::Vector2d> waypoints) {
  if (waypoints.size() > kMaxWaypoints) {
    throw TrajectoryError(TrajectoryErrc::kTooManyPoints, "trajectory has " + std::to_string(waypoints.size()) +
                                                              " waypoints, more than the limit of " +
                                                              std::to_string(kMaxWaypoints));
  }
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    if (!waypoints[i].allFinite()) {
      throw TrajectoryError(TrajectoryErrc::kNonFinitePoint,
                            "trajectory waypoint " + std::to_string(i) + " is not finite");
    }
  }
  points_.reserve(waypoints.size());
  for (const Eigen::Vector2d& w : waypoints) {
    if (points_.empty() || w != points_.back()) points_.push_back(w);
  }
  if (points_.size() < 2) {
    throw TrajectoryError(TrajectoryErrc::kTooFewPoints,
                          "trajectory needs at least two distinct waypoints, got " + std::to_string(points_.size()));
  }
  const std::size_t segments = points_.size() - 1;
  direction_.resize(segments);
  heading_rad_.resize(segments);
  cum_s_.resize(points_.size());
  cum_s_[0] = 0.0;
  for (std::size_t i = 0; i < segments; ++i) {
    const Eigen::Vector2d delta = points_[i + 1] - points_[i];
    const double length = delta.norm();
    direction_[i] = delta / length;
    heading_rad_[i] = std::atan2(delta.y(), delta.x());
    cum_s_[i + 1] = cum_s_[i] + length;
  }
  if (!(cum_s_.back() > 0.0) || !std::isfinite(cum_s_.back())) {
    throw TrajectoryError(TrajectoryErrc::kTooFewPoints, "trajectory length is zero or overflows");
  }
}

std::size_t Trajectory::segment_at(double s_m) const noexcept {
  // First waypoint with cum_s > s, minus one: the segment whose start is at or before s.
  const auto it = std::upper_bound(cum_s_.begin(), cum_s_.end(), s_m);
  const auto after = static_cast<std::size_t>(it - cum_s_.begin());
  if (after == 0) return 0;
  return std::min(after - 1, segment_count() - 1);
}

Eigen::Vector2d Trajectory::point_at(double s_m) const noexcept {
  const double s = std::clamp(s_m, 0.0, length_m());
  const std::size_t i = segment_at(s);
  return points_[i] + direction_[i] * (s - cum_s_[i]);
}

double Trajectory::heading_at(double s_m) const noexcept {
  return heading_rad_[segment_at(std::clamp(s_m, 0.0, length_m()))];
}

Projection Trajectory::project(const Eigen::Vector2d& position) const noexcept {
  return project_range(position, 0.0, length_m());
}

Projection Trajectory::project(const Eigen::Vector2d& position, double s_hint_m, double max_advance_m) const noexcept {
  const double lo = std::clamp(s_hint_m, 0.0, length_m());
  const double hi = std::clamp(lo + std::max(max_advance_m, 0.0), lo, length_m());
  return project_range(position, lo, hi);
}

Projection Trajectory::project_range(const Eigen::Vector2d& position, double s_lo, double s_hi) const noexcept {
  Projection best{s_lo, std::numeric_limits<double>::infinity(), point_at(s_lo)};
  const std::size_t first = segment_at(s_lo);
  const std::size_t last = segment_at(s_hi);
  for (std::size_t i = first; i <= last; ++i) {
    const double seg_lo = std::max(cum_s_[i], s_lo) - cum_s_[i];
    const double seg_hi = std::min(cum_s_[i + 1], s_hi) - cum_s_[i];
    const double along = std::clamp((position - points_[i]).dot(direction_[i]), seg_lo, seg_hi);
    const Eigen::Vector2d candidate = points_[i] + direction_[i] * along;
    const double distance = (position - candidate).norm();
    if (distance < best.distance_m) best = Projection{cum_s_[i] + along, distance, candidate};
  }
  return best;
}

Trajectory parse_trajectory_csv(std::string_view text, std::string_view source_name) {
  std::vector<Eigen::Vector2d> waypoints;
  std::size_t line_number = 0;
  for_each_line(text, [&](std::string_view line) {
    ++line_number;
    const std::string_view content = strip_comment_and_space(line);
    if (content.empty()) return;
    double values[2];
    if (parse_csv_doubles(content, values) != 2) {
      throw TrajectoryError(TrajectoryErrc::kParse, std::string(source_name) + ":" + std::to_string(line_number) +
                                                        ": expected 'x,y' (metres), got '" + std::string(content) +
                                                        "'");
    }
    if (!std::isfinite(values[0]) || !std::isfinite(values[1])) {
      throw TrajectoryError(TrajectoryErrc::kNonFinitePoint,
                            std::string(source_name) + ":" + std::to_string(line_number) +
                                ": waypoint is not finite: '" + std::string(content) + "'");
    }
    waypoints.emplace_back(values[0], values[1]);
  });
  try {
    return Trajectory(std::move(waypoints));
  } catch (const TrajectoryError& e) {
    throw TrajectoryError(e.code(), std::string(source_name) + ": " + e.what());
  }
}

}  // namespace trajroi::roi
