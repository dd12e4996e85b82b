#include "trajroi/roi/roi_chain.hpp"

namespace trajroi::roi {
namespace {

// A placeholder size for the shape not configured: valid, never built.
constexpr double kUnusedSize_m = 1.0;

double radius_or_unused(RoiShape shape, const ChainSize& size) {
  return shape == RoiShape::kCircular ? size.radius_m : kUnusedSize_m;
}

}  // namespace

RoiChain::RoiChain(RoiShape shape, const ChainSize& initial, ZLimits z)
    : shape_(shape),
      circles_(radius_or_unused(shape, initial), {}, z),
      rects_(shape == RoiShape::kRectangular ? initial.height_m : kUnusedSize_m,
             shape == RoiShape::kRectangular ? initial.width_m : kUnusedSize_m, {}, z) {}

void RoiChain::place(const Trajectory& trajectory, double s0_m, double look_ahead_m, double spacing_m,
                     const ChainSize& size) {
  place_centres(trajectory, s0_m, look_ahead_m, spacing_m, centres_);
  if (shape_ == RoiShape::kCircular) {
    circles_.assign(centres_, size.radius_m);
    circle_grid_.build(circles_);
  } else {
    rects_.assign(centres_, size.height_m, size.width_m);
    rect_grid_.build(rects_);
  }
}

FilterStats RoiChain::filter(std::span<const PointXYZI> points, IndexVector& kept) const {
  return shape_ == RoiShape::kCircular ? circle_grid_.filter(points, kept) : rect_grid_.filter(points, kept);
}

FilterStats RoiChain::filter(std::span<const PointXYZd> points, IndexVector& kept) const {
  return shape_ == RoiShape::kCircular ? circle_grid_.filter(points, kept) : rect_grid_.filter(points, kept);
}

ScanCalibration RoiChain::calibrate() const {
  return shape_ == RoiShape::kCircular ? circle_grid_.calibrate() : rect_grid_.calibrate();
}

}  // namespace trajroi::roi
