#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "trajroi/roi/centres.hpp"
#include "trajroi/roi/trajectory.hpp"

namespace trajroi::roi {

// The two ROI chain shapes of the paper, as the daemon, the evaluations and the tools name
// them ("circular", "rectangular").
enum class RoiShape : std::uint8_t { kCircular, kRectangular };
[[nodiscard]] constexpr std::string_view to_string(RoiShape shape) noexcept {
  return shape == RoiShape::kCircular ? "circular" : "rectangular";
}

// Axis-aligned box in the global XY plane (metres).
struct Box {
  double x_min;
  double y_min;
  double x_max;
  double y_max;
};

// Optional global-frame height limits, inclusive: z_min ≤ z ≤ z_max (defaults: no limit).
struct ZLimits {
  double min_m = -std::numeric_limits<double>::infinity();
  double max_m = std::numeric_limits<double>::infinity();
  [[nodiscard]] bool contains(double z) const noexcept { return z >= min_m && z <= max_m; }
};

// How one ROI relates to a whole cell of the fast filter's grid, decided with a margin so
// that rounding in the per-point test can never contradict it.
enum class CellRelation : unsigned char {
  kOutside,   // no point of the cell can pass this ROI's test
  kInside,    // every point of the cell passes this ROI's test
  kBoundary,  // undecided: points in the cell must be tested against this ROI
};

// ----------------------------------------------------------------------------------------
// Equation (1): p is in the circle around c when ‖p − c‖_XY ≤ r. Both the reference double
// loop and the fast filter call exactly this, so they round identically.
[[nodiscard]] inline bool circle_contains(double cx, double cy, double radius_m, double px, double py) noexcept {
  const double dx = px - cx;
  const double dy = py - cy;
  return std::sqrt(dx * dx + dy * dy) <= radius_m;
}

// A chain of circular ROIs of radius r. Throws std::invalid_argument when the radius is not
// finite and positive or the z limits are NaN or inverted.
class CircularRoiSet {
 public:
  CircularRoiSet(double radius_m, std::span<const Centre> centres, ZLimits z = {});
  // Replaces the centres, reusing storage (no allocation once the capacity suffices).
  void assign(std::span<const Centre> centres);
  // … and the radius (checked as in the constructor).
  void assign(std::span<const Centre> centres, double radius_m);

  [[nodiscard]] std::size_t size() const noexcept { return cx_.size(); }
  [[nodiscard]] double radius_m() const noexcept { return radius_m_; }
  [[nodiscard]] const ZLimits& z_limits() const noexcept { return z_; }
  [[nodiscard]] bool contains(std::size_t j, double px, double py) const noexcept {
    return circle_contains(cx_[j], cy_[j], radius_m_, px, py);
  }
  [[nodiscard]] Box bounds(std::size_t j) const noexcept {
    return {cx_[j] - radius_m_, cy_[j] - radius_m_, cx_[j] + radius_m_, cy_[j] + radius_m_};
  }
  [[nodiscard]] CellRelation relation(std::size_t j, const Box& cell, double tolerance_m) const noexcept;
  // The grid cell size that keeps the boundary band thin without too many cells.
  [[nodiscard]] double cell_size_hint_m() const noexcept { return radius_m_ / 8.0; }

 private:
  double radius_m_;
  ZLimits z_;
  std::vector<double> cx_;
  std::vector<double> cy_;
};

// ----------------------------------------------------------------------------------------
// Algorithm 2, lines 6–10: vertices A, B, C of the rectangle of height a (along the tangent)
// and width b (across) centred on c with tangent angle θ, and the edge vectors the test
// needs. Computed once per ROI, exactly as the paper writes it.
struct RectGeometry {
  double ax, ay;    // A = c − u − v
  double bx, by;    // B = c − u + v
  double abx, aby;  // AB = B − A
  double bcx, bcy;  // BC = C − B
  double ab2;       // ‖AB‖²
  double bc2;       // ‖BC‖²
  double ab;        // ‖AB‖ (for the grid's margins only; the test uses the squares)
  double bc;        // ‖BC‖
};

[[nodiscard]] RectGeometry make_rect_geometry(double cx, double cy, double theta_rad, double height_m,
                                              double width_m) noexcept;

// Equation (2): 0 ≤ AB·AP ≤ ‖AB‖² and 0 ≤ BC·BP ≤ ‖BC‖².
[[nodiscard]] inline bool rect_contains(const RectGeometry& g, double px, double py) noexcept {
  const double f1 = g.abx * (px - g.ax) + g.aby * (py - g.ay);
  if (!(0.0 <= f1 && f1 <= g.ab2)) return false;
  const double f2 = g.bcx * (px - g.bx) + g.bcy * (py - g.by);
  return 0.0 <= f2 && f2 <= g.bc2;
}

// A chain of rectangular ROIs of height a (along the tangent) and width b (across).
// Throws std::invalid_argument when a or b is not finite and positive.
class RectangularRoiSet {
 public:
  RectangularRoiSet(double height_m, double width_m, std::span<const Centre> centres, ZLimits z = {});
  void assign(std::span<const Centre> centres);
  void assign(std::span<const Centre> centres, double height_m, double width_m);

  [[nodiscard]] std::size_t size() const noexcept { return rects_.size(); }
  [[nodiscard]] double height_m() const noexcept { return height_m_; }
  [[nodiscard]] double width_m() const noexcept { return width_m_; }
  [[nodiscard]] const ZLimits& z_limits() const noexcept { return z_; }
  [[nodiscard]] const RectGeometry& geometry(std::size_t j) const noexcept { return rects_[j]; }
  [[nodiscard]] bool contains(std::size_t j, double px, double py) const noexcept {
    return rect_contains(rects_[j], px, py);
  }
  [[nodiscard]] Box bounds(std::size_t j) const noexcept;
  [[nodiscard]] CellRelation relation(std::size_t j, const Box& cell, double tolerance_m) const noexcept;
  [[nodiscard]] double cell_size_hint_m() const noexcept { return std::min(height_m_, width_m_) / 8.0; }

 private:
  double height_m_;
  double width_m_;
  ZLimits z_;
  std::vector<RectGeometry> rects_;
};

// ----------------------------------------------------------------------------------------
// The exact corridor: points within w/2 of the trajectory between arc lengths s0 and s1,
// i.e. the union of one capsule per polyline piece. It is the ground-truth labeller of the
// evaluations, and a filter in its own right.
[[nodiscard]] inline bool capsule_contains(double ax, double ay, double dx, double dy, double length2,
                                           double half_width_m, double px, double py) noexcept {
  const double apx = px - ax;
  const double apy = py - ay;
  double t = length2 > 0.0 ? (apx * dx + apy * dy) / length2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = apx - t * dx;
  const double ey = apy - t * dy;
  return std::sqrt(ex * ex + ey * ey) <= half_width_m;
}

class CorridorRoiSet {
 public:
  // Throws std::invalid_argument when the width is not finite and positive; s0 and s1 are
  // clamped to the trajectory and may be equal (a disc around one point).
  CorridorRoiSet(const Trajectory& trajectory, double s0_m, double s1_m, double width_m, ZLimits z = {});
  void assign(const Trajectory& trajectory, double s0_m, double s1_m);

  [[nodiscard]] std::size_t size() const noexcept { return ax_.size(); }
  [[nodiscard]] double width_m() const noexcept { return 2.0 * half_width_m_; }
  [[nodiscard]] const ZLimits& z_limits() const noexcept { return z_; }
  [[nodiscard]] bool contains(std::size_t j, double px, double py) const noexcept {
    return capsule_contains(ax_[j], ay_[j], dx_[j], dy_[j], length2_[j], half_width_m_, px, py);
  }
  [[nodiscard]] Box bounds(std::size_t j) const noexcept;
  [[nodiscard]] CellRelation relation(std::size_t j, const Box& cell, double tolerance_m) const noexcept;
  [[nodiscard]] double cell_size_hint_m() const noexcept { return half_width_m_ / 4.0; }

 private:
  double half_width_m_;
  ZLimits z_;
  std::vector<double> ax_, ay_, dx_, dy_, length2_;
};

// ----------------------------------------------------------------------------------------
// Cell relations, inline: GridFilter::build() calls them for every (ROI, cell) pair.
namespace detail {
// Squared distance from (px, py) to the box: 0 inside it.
inline double box_distance2(const Box& b, double px, double py) noexcept {
  const double dx = std::max({b.x_min - px, 0.0, px - b.x_max});
  const double dy = std::max({b.y_min - py, 0.0, py - b.y_max});
  return dx * dx + dy * dy;
}

// Squared distance from (px, py) to the farthest point of the box.
inline double box_far_distance2(const Box& b, double px, double py) noexcept {
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

inline SlabRange slab_range(double ox, double oy, double ex, double ey, const Box& cell) noexcept {
  const double mx = 0.5 * (cell.x_min + cell.x_max);
  const double my = 0.5 * (cell.y_min + cell.y_max);
  const double centre = ex * (mx - ox) + ey * (my - oy);
  const double reach = std::abs(ex) * 0.5 * (cell.x_max - cell.x_min) + std::abs(ey) * 0.5 * (cell.y_max - cell.y_min);
  return {centre - reach, centre + reach};
}

}  // namespace detail

inline CellRelation CircularRoiSet::relation(std::size_t j, const Box& cell, double tolerance_m) const noexcept {
  // Compared as squares (no square roots: the grid's build made up to two per cell and ROI).
  // The squares' rounding (a few ulps of r²) is far inside the margin, which is what keeps a
  // decision from contradicting the per-point test's.
  const double inner = radius_m_ - tolerance_m;
  if (inner >= 0.0 && detail::box_far_distance2(cell, cx_[j], cy_[j]) <= inner * inner) {
    return CellRelation::kInside;
  }
  const double outer = radius_m_ + tolerance_m;
  if (detail::box_distance2(cell, cx_[j], cy_[j]) > outer * outer) return CellRelation::kOutside;
  return CellRelation::kBoundary;
}

inline CellRelation RectangularRoiSet::relation(std::size_t j, const Box& cell, double tolerance_m) const noexcept {
  const RectGeometry& g = rects_[j];
  // f1 = AB·(p − A) ∈ [0, ‖AB‖²] and f2 = BC·(p − B) ∈ [0, ‖BC‖²]; f / ‖e‖ is a distance, so
  // a margin of tolerance_m metres is tolerance_m · ‖e‖ in f units.
  // The margin also absorbs the rounding of the centre-based range (a few ulps of f).
  const double tol1 = tolerance_m * g.ab;
  const double tol2 = tolerance_m * g.bc;
  const detail::SlabRange f1 = detail::slab_range(g.ax, g.ay, g.abx, g.aby, cell);
  const detail::SlabRange f2 = detail::slab_range(g.bx, g.by, g.bcx, g.bcy, cell);
  if (f1.max < -tol1 || f1.min > g.ab2 + tol1 || f2.max < -tol2 || f2.min > g.bc2 + tol2) {
    return CellRelation::kOutside;
  }
  if (f1.min >= tol1 && f1.max <= g.ab2 - tol1 && f2.min >= tol2 && f2.max <= g.bc2 - tol2) {
    return CellRelation::kInside;
  }
  return CellRelation::kBoundary;
}

}  // namespace trajroi::roi
