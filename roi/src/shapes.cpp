#include "trajroi/roi/shapes.hpp"

#include <array>
#include <stdexcept>
#include <string>

namespace trajroi::roi {
namespace {

void require_positive(double value, const char* what) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw std::invalid_argument(std::string(what) + " must be finite and positive, got " +
                                std::to_string(value));
  }
}

void require_valid(const ZLimits& z) {
  if (std::isnan(z.min_m) || std::isnan(z.max_m) || z.min_m > z.max_m) {
    throw std::invalid_argument("z limits must satisfy z_min <= z_max, got [" +
                                std::to_string(z.min_m) + ", " + std::to_string(z.max_m) + "]");
  }
}

// Squared distance from (px, py) to the box: 0 inside it.
double box_distance2(const Box& b, double px, double py) noexcept {
  const double dx = std::max({b.x_min - px, 0.0, px - b.x_max});
  const double dy = std::max({b.y_min - py, 0.0, py - b.y_max});
  return dx * dx + dy * dy;
}

// Squared distance from (px, py) to the farthest point of the box.
double box_far_distance2(const Box& b, double px, double py) noexcept {
  const double dx = std::max(px - b.x_min, b.x_max - px);
  const double dy = std::max(py - b.y_min, b.y_max - py);
  return dx * dx + dy * dy;
}

// Range of the linear function f(p) = e·(p − o) over a box: its value at the box's centre
// plus or minus its largest change towards a corner.
struct SlabRange {
  double min;
  double max;
};

SlabRange slab_range(double ox, double oy, double ex, double ey, const Box& cell) noexcept {
  const double mx = 0.5 * (cell.x_min + cell.x_max);
  const double my = 0.5 * (cell.y_min + cell.y_max);
  const double centre = ex * (mx - ox) + ey * (my - oy);
  const double reach = std::abs(ex) * 0.5 * (cell.x_max - cell.x_min) +
                       std::abs(ey) * 0.5 * (cell.y_max - cell.y_min);
  return {centre - reach, centre + reach};
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

CellRelation CircularRoiSet::relation(std::size_t j, const Box& cell,
                                      double tolerance_m) const noexcept {
  if (std::sqrt(box_far_distance2(cell, cx_[j], cy_[j])) <= radius_m_ - tolerance_m) {
    return CellRelation::kInside;
  }
  if (std::sqrt(box_distance2(cell, cx_[j], cy_[j])) > radius_m_ + tolerance_m) {
    return CellRelation::kOutside;
  }
  return CellRelation::kBoundary;
}

// ----------------------------------------------------------------------------------------
RectGeometry make_rect_geometry(double cx, double cy, double theta_rad, double height_m,
                                double width_m) noexcept {
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

RectangularRoiSet::RectangularRoiSet(double height_m, double width_m,
                                     std::span<const Centre> centres, ZLimits z)
    : height_m_(height_m), width_m_(width_m), z_(z) {
  require_positive(height_m, "rectangular ROI height a");
  require_positive(width_m, "rectangular ROI width b");
  require_valid(z);
  assign(centres);
}

void RectangularRoiSet::assign(std::span<const Centre> centres) {
  rects_.clear();
  for (const Centre& c : centres) {
    rects_.push_back(
        make_rect_geometry(c.position.x(), c.position.y(), c.theta_rad, height_m_, width_m_));
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

CellRelation RectangularRoiSet::relation(std::size_t j, const Box& cell,
                                         double tolerance_m) const noexcept {
  const RectGeometry& g = rects_[j];
  // f1 = AB·(p − A) ∈ [0, ‖AB‖²] and f2 = BC·(p − B) ∈ [0, ‖BC‖²]; f / ‖e‖ is a distance, so
  // a margin of tolerance_m metres is tolerance_m · ‖e‖ in f units.
  // The margin also absorbs the rounding of the centre-based range (a few ulps of f).
  const double tol1 = tolerance_m * g.ab;
  const double tol2 = tolerance_m * g.bc;
  const SlabRange f1 = slab_range(g.ax, g.ay, g.abx, g.aby, cell);
  const SlabRange f2 = slab_range(g.bx, g.by, g.bcx, g.bcy, cell);
  if (f1.max < -tol1 || f1.min > g.ab2 + tol1 || f2.max < -tol2 || f2.min > g.bc2 + tol2) {
    return CellRelation::kOutside;
  }
  if (f1.min >= tol1 && f1.max <= g.ab2 - tol1 && f2.min >= tol2 && f2.max <= g.bc2 - tol2) {
    return CellRelation::kInside;
  }
  return CellRelation::kBoundary;
}

// ----------------------------------------------------------------------------------------
CorridorRoiSet::CorridorRoiSet(const Trajectory& trajectory, double s0_m, double s1_m,
                               double width_m, ZLimits z)
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

CellRelation CorridorRoiSet::relation(std::size_t j, const Box& cell,
                                      double tolerance_m) const noexcept {
  // Distance to a segment is 1-Lipschitz: over the cell it stays within the half diagonal
  // of its value at the cell's centre.
  const double mx = 0.5 * (cell.x_min + cell.x_max);
  const double my = 0.5 * (cell.y_min + cell.y_max);
  const double half_diagonal = 0.5 * std::hypot(cell.x_max - cell.x_min, cell.y_max - cell.y_min);
  const double apx = mx - ax_[j];
  const double apy = my - ay_[j];
  const double t = length2_[j] > 0.0
                       ? std::clamp((apx * dx_[j] + apy * dy_[j]) / length2_[j], 0.0, 1.0)
                       : 0.0;
  const double centre_distance = std::hypot(apx - t * dx_[j], apy - t * dy_[j]);
  if (centre_distance + half_diagonal <= half_width_m_ - tolerance_m) return CellRelation::kInside;
  if (centre_distance - half_diagonal > half_width_m_ + tolerance_m) return CellRelation::kOutside;
  return CellRelation::kBoundary;
}

}  // namespace trajroi::roi
