#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "trajroi/roi/filter_stats.hpp"

namespace trajroi::roi {

// The paper's Algorithms 1 and 2 literally: for every point, try the ROIs in order and stop
// at the first that contains it (O(n·m)). Kept as the oracle the fast filter must equal.
//
// RoiSet is one of CircularRoiSet, RectangularRoiSet, CorridorRoiSet. `kept` is cleared and
// receives the indices of the kept points in ascending order; its capacity is reused.
template <typename RoiSet, typename Point>
FilterStats reference_filter(const RoiSet& rois, std::span<const Point> points, IndexVector& kept) {
  FilterStats stats;
  stats.input = points.size();
  kept.clear();
  const std::size_t m = rois.size();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto x = static_cast<double>(points[i].x);
    const auto y = static_cast<double>(points[i].y);
    const Precheck pre = precheck(rois.z_limits(), x, y, static_cast<double>(points[i].z));
    if (pre != Precheck::kPass) {
      count_rejection(stats, pre);
      continue;
    }
    for (std::size_t j = 0; j < m; ++j) {
      if (rois.contains(j, x, y)) {
        kept.push_back(static_cast<std::uint32_t>(i));
        break;
      }
    }
  }
  stats.kept = kept.size();
  return stats;
}

}  // namespace trajroi::roi
