#pragma once

// One trajectory ROI chain, as a sweep uses it: centres placed every d along the trajectory
// over the look-ahead (place_centres), the configured shape laid on them (circles of radius r,
// or rectangles a along the tangent × b across), the grid built over them (GridFilter), and
// points filtered against it, exactly. The daemon's per-sweep pipeline and the evaluations
// both use this one chain. Only the configured shape is ever built.
//
// Allocates nothing per place() or filter() once reserve() has sized it for the longest chain.
#include <cstddef>
#include <span>
#include <vector>

#include "trajroi/roi/centres.hpp"
#include "trajroi/roi/filter_stats.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/trajectory.hpp"

namespace trajroi::roi {

// The shape's size: `radius_m` for circles; `height_m` (along) and `width_m` (across) for
// rectangles. The other shape's fields are ignored.
struct ChainSize {
  double radius_m = 0.0;
  double height_m = 0.0;
  double width_m = 0.0;
};

class RoiChain {
 public:
  // `initial`: the size the shapes take until the first place() (must be valid for the shape).
  RoiChain(RoiShape shape, const ChainSize& initial, ZLimits z = {});

  void reserve(std::size_t centres) { centres_.reserve(centres); }

  // Centres every `spacing_m` from arc length `s0_m` over `look_ahead_m` (place_centres' rules
  // and errors), the shapes of `size` on them, and the grid over them.
  void place(const Trajectory& trajectory, double s0_m, double look_ahead_m, double spacing_m, const ChainSize& size);

  // The indices of the points inside the chain, into `kept` (cleared first). Double-precision
  // clouds (points read from text) are decided without rounding to float.
  FilterStats filter(std::span<const PointXYZI> points, IndexVector& kept) const;
  FilterStats filter(std::span<const PointXYZd> points, IndexVector& kept) const;

  // Times the scans on the placed chain and makes the fastest the one filter() runs
  // (GridFilter::calibrate).
  [[nodiscard]] ScanCalibration calibrate() const;

  [[nodiscard]] RoiShape shape() const noexcept { return shape_; }
  [[nodiscard]] const std::vector<Centre>& centres() const noexcept { return centres_; }

 private:
  RoiShape shape_;
  std::vector<Centre> centres_;
  CircularRoiSet circles_;
  RectangularRoiSet rects_;
  GridFilter<CircularRoiSet> circle_grid_;
  GridFilter<RectangularRoiSet> rect_grid_;
};

}  // namespace trajroi::roi
