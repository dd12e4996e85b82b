#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace trajroi::roi {

// Confusion counts of a filter against ground-truth labels, and the paper's equation (3).
//
// 0/0 convention: each ratio measures one kind of error, and when its denominator is zero no
// error of that kind can have been made, so the ratio is 1:
//   precision = 1 when nothing was kept (TP + FP = 0),
//   recall    = 1 when there is nothing to find (TP + FN = 0),
//   accuracy  = 1 for an empty cloud.
struct Confusion {
  std::uint64_t tp = 0;
  std::uint64_t fp = 0;
  std::uint64_t fn = 0;
  std::uint64_t tn = 0;

  [[nodiscard]] std::uint64_t total() const noexcept { return tp + fp + fn + tn; }
  [[nodiscard]] double precision() const noexcept;
  [[nodiscard]] double recall() const noexcept;
  [[nodiscard]] double accuracy() const noexcept;
};

// `kept`: ascending indices of the kept points; `truth[i]` non-zero when point i belongs to
// the ground-truth ROI. Throws std::out_of_range for an index past truth.size().
[[nodiscard]] Confusion confusion(std::span<const std::uint32_t> kept, std::span<const std::uint8_t> truth);

// Copies the kept points, in order, into `out` (cleared first; capacity reused).
template <typename Point>
void compact(std::span<const Point> points, std::span<const std::uint32_t> kept, std::vector<Point>& out) {
  out.clear();
  for (const std::uint32_t i : kept)
    out.push_back(points[i]);
}

}  // namespace trajroi::roi
