#include "trajroi/roi/shapes.hpp"

#include <array>
#include <stdexcept>
#include <string>

namespace trajroi::roi {
namespace {

void require_positive(double value, const char* what) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw std::invalid_argument(std::string(what) + " must be finite and positive, got " + std::to_string(value));
  }
}

void require_valid(const ZLimits& z) {
  if (std::isnan(z.min_m) || std::isnan(z.max_m) || z.min_m > z.max_m) {
    throw std::invalid_argument("z limits must satisfy z_min <= z_max, got [" + std::to_string(z.min_m) + ", " +
                                std::to_string(z.max_m) + "]");
  }
}

}  // namespace

// ----------------------------------------------------------------------------------------
CircularRoiSet::CircularRoiSet(double radius_m, std::span<const Centre> centres, ZLimits z)
    : radius_m_(radius_m), z_(z) {
  require_positive(radius_m, "circular ROI radius");
  require_valid(z);
  assign(centres);
}

void CircularRoiSet::assign(std::span<const Centre> centres) {
  cx_.clear();
  cy_.clear();
  for (const Centre& c : centres) {
    cx_.push_back(c.position.x());
    cy_.push_back(c.position.y());
  }
}

void CircularRoiSet::assign(std::span<const Centre> centres, double radius_m) {
  require_positive(radius_m, "circular ROI radius");
  radius_m_ = radius_m;
  assign(centres);
}

// ----------------------------------------------------------------------------------------
RectGeometry make_rect_geometry(double cx, double cy, double theta_rad, double height_m, double width_m) noexcept {
  // u = a/2 (cos θ, sin θ);  v = b / (2‖u‖) · (u_y, −u_x)
  const double ux = height_m / 2.0 * std::cos(theta_rad);
  const double uy = height_m / 2.0 * std::sin(theta_rad);
  const double scale = width_m / (2.0 * std::sqrt(ux * ux + uy * uy));
  const double vx = scale * uy;
  const double vy = scale * -ux;
  const double ax = cx - ux - vx;
  const double ay = cy - uy - vy;
  const double bx = cx - ux + vx;
  const double by = cy - uy + vy;
  const double ccx = cx + ux + vx;
  const double ccy = cy + uy + vy;
  RectGeometry g{};
  g.ax = ax;
  g.ay = ay;
  g.bx = bx;
  g.by = by;
  g.abx = bx - ax;
  g.aby = by - ay;
  g.bcx = ccx - bx;
  g.bcy = ccy - by;
  g.ab2 = g.abx * g.abx + g.aby * g.aby;
  g.bc2 = g.bcx * g.bcx + g.bcy * g.bcy;
  g.ab = std::sqrt(g.ab2);
  g.bc = std::sqrt(g.bc2);
  return g;
}

RectangularRoiSet::RectangularRoiSet(double height_m, double width_m, std::span<const Centre> centres, ZLimits z)
    : height_m_(height_m), width_m_(width_m), z_(z) {
  require_positive(height_m, "rectangular ROI height a");
  require_positive(width_m, "rectangular ROI width b");
  require_valid(z);
  assign(centres);
}

void RectangularRoiSet::assign(std::span<const Centre> centres) {
  rects_.clear();
  for (const Centre& c : centres) {
    rects_.push_back(make_rect_geometry(c.position.x(), c.position.y(), c.theta_rad, height_m_, width_m_));
  }
}

void RectangularRoiSet::assign(std::span<const Centre> centres, double height_m, double width_m) {
  require_positive(height_m, "rectangular ROI height a");
  require_positive(width_m, "rectangular ROI width b");
  height_m_ = height_m;
  width_m_ = width_m;
  assign(centres);
}

Box RectangularRoiSet::bounds(std::size_t j) const noexcept {
  // The region the test accepts is the parallelogram A + s·AB + t·BC, s, t ∈ [0, 1].
  const RectGeometry& g = rects_[j];
  const std::array<double, 4> xs{g.ax, g.ax + g.abx, g.ax + g.bcx, g.ax + g.abx + g.bcx};
  const std::array<double, 4> ys{g.ay, g.ay + g.aby, g.ay + g.bcy, g.ay + g.aby + g.bcy};
  return {*std::min_element(xs.begin(), xs.end()), *std::min_element(ys.begin(), ys.end()),
          *std::max_element(xs.begin(), xs.end()), *std::max_element(ys.begin(), ys.end())};
}

// ----------------------------------------------------------------------------------------
CorridorRoiSet::CorridorRoiSet(const Trajectory& trajectory, double s0_m, double s1_m, double width_m, ZLimits z)
    : half_width_m_(width_m / 2.0), z_(z) {
  require_positive(width_m, "corridor width");
  require_valid(z);
  assign(trajectory, s0_m, s1_m);
}

void CorridorRoiSet::assign(const Trajectory& trajectory, double s0_m, double s1_m) {
  ax_.clear();
  ay_.clear();
  dx_.clear();
  dy_.clear();
  length2_.clear();
  const double length = trajectory.length_m();
  const double s0 = std::clamp(std::isnan(s0_m) ? 0.0 : s0_m, 0.0, length);
  const double s1 = std::clamp(std::isnan(s1_m) ? length : s1_m, s0, length);
  auto add_piece = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    ax_.push_back(a.x());
    ay_.push_back(a.y());
    dx_.push_back(b.x() - a.x());
    dy_.push_back(b.y() - a.y());
    length2_.push_back(dx_.back() * dx_.back() + dy_.back() * dy_.back());
  };
  Eigen::Vector2d previous = trajectory.point_at(s0);
  const std::size_t last_segment = trajectory.segment_at(s1);
  for (std::size_t i = trajectory.segment_at(s0) + 1; i <= last_segment; ++i) {
    if (trajectory.s_at_waypoint(i) >= s1) break;
    const Eigen::Vector2d& w = trajectory.waypoints()[i];
    add_piece(previous, w);
    previous = w;
  }
  add_piece(previous, trajectory.point_at(s1));
}

Box CorridorRoiSet::bounds(std::size_t j) const noexcept {
  const double bx = ax_[j] + dx_[j];
  const double by = ay_[j] + dy_[j];
  return {std::min(ax_[j], bx) - half_width_m_, std::min(ay_[j], by) - half_width_m_,
          std::max(ax_[j], bx) + half_width_m_, std::max(ay_[j], by) + half_width_m_};
}

CellRelation CorridorRoiSet::relation(std::size_t j, const Box& cell, double tolerance_m) const noexcept {
  // Distance to a segment is 1-Lipschitz: over the cell it stays within the half diagonal
  // of its value at the cell's centre.
  const double mx = 0.5 * (cell.x_min + cell.x_max);
  const double my = 0.5 * (cell.y_min + cell.y_max);
  const double half_diagonal = 0.5 * std::hypot(cell.x_max - cell.x_min, cell.y_max - cell.y_min);
  const double apx = mx - ax_[j];
  const double apy = my - ay_[j];
  const double t = length2_[j] > 0.0 ? std::clamp((apx * dx_[j] + apy * dy_[j]) / length2_[j], 0.0, 1.0) : 0.0;
  const double centre_distance = std::hypot(apx - t * dx_[j], apy - t * dy_[j]);
  if (centre_distance + half_diagonal <= half_width_m_ - tolerance_m) return CellRelation::kInside;
  if (centre_distance - half_diagonal > half_width_m_ + tolerance_m) return CellRelation::kOutside;
  return CellRelation::kBoundary;
}

}  // namespace trajroi::roi
