#pragma once

// The grid filter's per-point pieces that every scan shares (grid_filter.cpp, the SSE2, AVX2
// and AVX-512 scans in grid_filter_sse2.cpp, grid_filter_avx2.cpp, grid_filter_avx512.cpp):
// locating a point's cell, deciding a boundary cell or sub-cell, the scalar path, and the
// prefetching of large clouds. Inline, so each scan's translation unit compiles them into its
// own loops. Internal to roi/src.
#include <algorithm>
#include <cstdint>
#include <span>

#include "trajroi/roi/grid_filter.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace trajroi::roi {

template <typename RoiSet>
inline std::size_t GridFilter<RoiSet>::cell_index(float x, float y) const noexcept {
  // The same float operations as the SSE2 path: identical cells on either path.
  const float fx = (x - x0_) * inv_cell_;
  const float fy = (y - y0_) * inv_cell_;
  const bool on_grid =
      fx >= 0.0f && fx < static_cast<float>(nx_) && fy >= 0.0f && fy < static_cast<float>(ny_);  // false for NaN
  if (!on_grid) return cells_.size() - 1;
  const auto ix = static_cast<float>(static_cast<std::int32_t>(fx));
  const auto iy = static_cast<float>(static_cast<std::int32_t>(fy));
  return static_cast<std::size_t>(static_cast<std::int32_t>(iy * static_cast<float>(nx_) + ix));
}

template <typename RoiSet>
inline std::uint32_t GridFilter<RoiSet>::decide(std::uint32_t cell, double x, double y) const noexcept {
  if (cell < kFirstBoundary) return cell;  // kOutside = 0, kInside = 1
  // The sub-cell from the same float arithmetic that chose the cell: its integer part is
  // the cell, its fraction (exact in float) the position inside it.
  const float fx = (static_cast<float>(x) - x0_) * inv_cell_;
  const float fy = (static_cast<float>(y) - y0_) * inv_cell_;
  const float frac_x = fx - static_cast<float>(static_cast<std::int32_t>(fx));
  const float frac_y = fy - static_cast<float>(static_cast<std::int32_t>(fy));
  const std::uint32_t sx = std::min(static_cast<std::uint32_t>(frac_x * kSub), kSub - 1);
  const std::uint32_t sy = std::min(static_cast<std::uint32_t>(frac_y * kSub), kSub - 1);
  return decide_sub(sub_[static_cast<std::size_t>(cell - kFirstBoundary) * kSub * kSub + sy * kSub + sx], x, y);
}

template <typename RoiSet>
inline std::uint32_t GridFilter<RoiSet>::decide_sub(std::uint32_t sub, double x, double y) const noexcept {
  if (sub < kFirstBoundary) return sub;
  const std::uint32_t id = sub - kFirstBoundary;
  for (std::uint32_t k = sub_offsets_[id]; k < sub_offsets_[id + 1]; ++k) {
    if (rois_->contains(sub_candidates_[k], x, y)) return 1;
  }
  return 0;
}

template <typename RoiSet>
template <typename Point>
inline void GridFilter<RoiSet>::scalar_point(std::span<const Point> points, std::size_t i, Scan& scan) const {
  const auto x = static_cast<double>(points[i].x);
  const auto y = static_cast<double>(points[i].y);
  const auto z = static_cast<double>(points[i].z);
  const ZLimits& z_limits = rois_->z_limits();
  const Precheck pre = precheck(z_limits, x, y, z);
  if (pre != Precheck::kPass) [[unlikely]] {
    count_rejection(*scan.stats, pre);
    return;
  }
  scan.out[scan.count] = static_cast<std::uint32_t>(i);
  scan.count += decide(cells_[cell_index(static_cast<float>(x), static_cast<float>(y))], x, y);
}

template <typename RoiSet>
inline unsigned GridFilter<RoiSet>::decide_lanes(unsigned boundary, const std::uint32_t* sub_index,
                                                 std::span<const PointXYZI> points, std::size_t first) const {
  // Most boundary lanes fall in a sub-cell that is inside or outside: those are read without
  // a branch, and only the lanes in boundary sub-cells (about one in four) test candidates.
  unsigned keep = 0;
  unsigned undecided = 0;
  for (; boundary != 0; boundary &= boundary - 1) {
    const auto k = static_cast<unsigned>(__builtin_ctz(boundary));
    const std::uint32_t value = sub_[sub_index[k]];
    keep |= static_cast<unsigned>(value == kInside) << k;
    undecided |= static_cast<unsigned>(value >= kFirstBoundary) << k;
  }
  for (; undecided != 0; undecided &= undecided - 1) {
    const auto k = static_cast<unsigned>(__builtin_ctz(undecided));
    keep |= decide_sub(sub_[sub_index[k]], static_cast<double>(points[first + k].x),
                       static_cast<double>(points[first + k].y))
            << k;
  }
  return keep;
}

// Vector scans over PointXYZI clouds. A PointXYZI is exactly one 16-byte vector (x, y, z,
// intensity); the scans compute the cell of each point with the same float operations as
// cell_index(), so every path assigns every point the same cell. A block in which a point is
// non-finite or outside the z limits is handed to the scalar code point by point (which
// counts the rejections); points in boundary cells are decided by decide() one by one in
// the SSE2 scan (the whole block), and in the AVX2 and AVX-512 scans by decide_sub(), their
// sub-cells located for all those lanes at once. All return the index of the first point
// they did not process.
#if defined(__x86_64__) || defined(__i386__)
namespace detail {
// The scans read the cloud once, front to back, and do little with each cache line: the
// hardware prefetcher alone leaves them waiting on memory for a cloud larger than the cache
// (the accumulated 2.88 M-point cloud ran at 1.0–1.4× a memcpy of it on a 2-core Xeon VM;
// asking for each line 8 KiB ahead brought it to 0.55–0.85×, six interleaved runs each).
// Each step of a scan asks for the lines it will read that far ahead, one per line. The
// address is formed as an integer: it may lie past the cloud (a prefetch never faults).
// Only a cloud too large for the caches is streamed so: the daemon scans each packet's few
// hundred points just after placing them (in L1), where prefetches that far ahead would fetch
// lines past the batch. A smaller cloud asks for the lines it is reading (no branch in the
// loop, no line fetched for nothing).
inline constexpr std::size_t kPrefetchAhead_bytes = 8192;
inline constexpr std::size_t kCacheLine_bytes = 64;
inline constexpr std::size_t kStreamFrom_bytes = std::size_t{1} << 20;
[[nodiscard]] inline std::size_t prefetch_distance(std::span<const PointXYZI> points) noexcept {
  return points.size_bytes() >= kStreamFrom_bytes ? kPrefetchAhead_bytes : 0;
}
template <std::size_t kBytes>
__attribute__((always_inline)) inline void prefetch_ahead(const float* step, std::size_t distance) {
  static_assert(kBytes % kCacheLine_bytes == 0);
  const auto at = reinterpret_cast<std::uintptr_t>(step) + distance;
  for (std::size_t line = 0; line < kBytes; line += kCacheLine_bytes)
    _mm_prefetch(reinterpret_cast<const char*>(at + line), _MM_HINT_T0);
}
}  // namespace detail
#endif  // x86

}  // namespace trajroi::roi
