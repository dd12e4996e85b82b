#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "trajroi/roi/filter_stats.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/shapes.hpp"

// A member the vector scans call into plain x86-64 code: never inlined, and (GCC) never
// replaced by a clone with its own calling convention (see GridFilter::scalar_block).
#if defined(__clang__)
#define TRAJROI_STANDARD_CALL __attribute__((noinline))
#else
#define TRAJROI_STANDARD_CALL __attribute__((noipa))
#endif

namespace trajroi::roi {

enum class SimdPath : unsigned char { kAuto, kAvx512, kAvx2, kSse2, kScalar };

[[nodiscard]] const char* to_string(SimdPath path) noexcept;
// "avx512", "avx2", "sse2", "scalar" or "auto" (also empty) → the path; false for anything else.
[[nodiscard]] bool simd_path_from_string(const char* text, SimdPath& path) noexcept;
// Whether this CPU can run the path (kAuto and kScalar: always).
[[nodiscard]] bool cpu_has(SimdPath path) noexcept;

// What GridFilter::calibrate() measured: nanoseconds per point of each scan on this machine
// (indexed by SimdPath; negative for a scan the CPU lacks) and the one kAuto now runs.
struct ScanCalibration {
  SimdPath chosen = SimdPath::kAuto;
  bool forced = false;  // TRAJROI_SIMD named the path: nothing was timed
  double ns_per_point[5] = {-1.0, -1.0, -1.0, -1.0, -1.0};
};

// The float nearest to v on the given side (v itself when exactly representable).
[[nodiscard]] inline float float_at_or_below(double v) noexcept {
  const auto f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
[[nodiscard]] inline float float_at_or_above(double v) noexcept {
  const auto f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// The z limits as the floats they admit, for the vector scans: for a float z,
// z ≥ lo ⇔ (double) z ≥ z_min and z ≤ hi ⇔ (double) z ≤ z_max. `limited` is false when no
// limit is set (then only finiteness is checked).
struct FloatZLimits {
  float lo;
  float hi;
  bool limited;
};
[[nodiscard]] inline FloatZLimits float_z_limits(const ZLimits& z) noexcept {
  constexpr auto kMax = static_cast<double>(std::numeric_limits<float>::max());
  return {float_at_or_above(std::max(z.min_m, -kMax)), float_at_or_below(std::min(z.max_m, kMax)),
          std::isfinite(z.min_m) || std::isfinite(z.max_m)};
}

// The fast filter: the same membership decision as reference_filter for every point, bit for
// bit, at a per-point cost that does not grow with the number of ROIs.
//
// build() lays a uniform grid over the chain's bounding box and classifies every cell, with a
// margin far larger than rounding error, as outside every ROI, inside at least one ROI, or
// boundary. A boundary cell is split into 4 × 4 sub-cells, classified the same way against
// the cell's candidates; a boundary sub-cell keeps the list of ROIs that may contain some of
// its points, nearest first. A point there is decided by calling the same
// RoiSet::contains() the reference calls, on those candidates only. Since every ROI left out
// of the list rejects the point for sure, and any ROI that accepts it makes the reference
// keep it, both agree. Cells are located in float, and every (sub-)cell is classified as if
// enlarged by a margin that covers float rounding, so a point placed in a neighbouring cell
// is still covered by that cell's classification.
//
// A filter() call allocates nothing once `kept` has the capacity; build() reuses its storage.
//
// Implemented in roi/src/grid_filter.cpp (the build and the SSE2, AVX2 and AVX-512 scans,
// chosen at run time) and instantiated there for the three shapes (CircularRoiSet,
// RectangularRoiSet, CorridorRoiSet) and both point types (PointXYZI, PointXYZd).
template <typename RoiSet>
class GridFilter {
 public:
  // Cell count ceiling: 4 M cells (16 MiB); a larger area gets coarser cells, still exact.
  static constexpr std::size_t kMaxCells = std::size_t{1} << 22;

  // `rois` must stay alive and unchanged until the next build().
  void build(const RoiSet& rois);

  // `path` chooses the implementation of the per-point scan for PointXYZI clouds (other point
  // types always take the scalar path); every path gives the same result. kAuto takes the
  // one calibrate() found fastest, else the widest the CPU supports; the others exist so
  // tests and benchmarks can run each one (a path the CPU lacks falls back to the next
  // narrower one).
  template <typename Point>
  FilterStats filter(std::span<const Point> points, IndexVector& kept, SimdPath path = SimdPath::kAuto) const;

  // Which scan is fastest depends on the processor, not only on what it supports (the AVX2
  // scan's gathers are slower than SSE2 on some AMD Zen for rectangles). Times each scan the
  // CPU has on a synthetic LiDAR-like cloud laid over this (built) grid, best of several
  // runs, and makes the fastest the one kAuto runs for this shape, process-wide, from then on.
  // TRAJROI_SIMD=avx512|avx2|sse2|scalar in the environment forces a path instead (tests,
  // benchmarks). Thread-safe; a few milliseconds. Until it is called kAuto runs the widest.
  ScanCalibration calibrate() const;
  // The scan kAuto runs now for this shape.
  [[nodiscard]] static SimdPath auto_path() noexcept;

  [[nodiscard]] std::size_t cell_count() const noexcept { return nx_ * ny_; }
  [[nodiscard]] std::size_t boundary_cell_count() const noexcept { return offsets_.empty() ? 0 : offsets_.size() - 1; }
  [[nodiscard]] double cell_size_m() const noexcept { return cell_size_m_; }

 private:
  static constexpr std::uint32_t kOutside = 0;
  static constexpr std::uint32_t kInside = 1;
  static constexpr std::uint32_t kFirstBoundary = 2;  // cell value = boundary id + 2
  // The scans add a cell's value to the count and read an all-zero register as outside.
  static_assert(kOutside == 0 && kInside == 1);

  struct Scan {
    std::uint32_t* out;  // room for every point
    std::size_t count;   // indices written so far
    FilterStats* stats;
  };
  template <typename Point>
  void scalar_point(std::span<const Point> points, std::size_t i, Scan& scan) const;
#if defined(__x86_64__) || defined(__i386__)
  std::size_t scan_sse2(std::span<const PointXYZI> points, Scan& scan) const;
  __attribute__((target("avx2,popcnt"))) std::size_t scan_avx2(std::span<const PointXYZI> points, Scan& scan) const;
  __attribute__((target("avx512f,avx512dq,popcnt"))) std::size_t scan_avx512(std::span<const PointXYZI> points,
                                                                             Scan& scan) const;
  // For the vector scans. The points first … first + n − 1 one by one, `count` indices
  // written so far; returns the new count. Never inlined nor cloned: the scans reach this
  // plain x86-64 code through a call of the standard ABI, before which the compiler clears
  // the upper vector state (GCC 12 left it dirty for calls to its own clones, and every SSE
  // instruction of the callee then paid for a merge with it).
  TRAJROI_STANDARD_CALL std::size_t scalar_block(std::span<const PointXYZI> points, std::size_t first, std::size_t n,
                                                 Scan& scan, std::size_t count) const;
  // Bit k set for each lane k of `boundary` whose point first + k is kept, given the indices
  // of the lanes' sub-cells in sub_. Inlined into each scan, so that it is compiled for the
  // scan's instruction set.
  [[nodiscard]] __attribute__((always_inline)) inline unsigned decide_lanes(unsigned boundary,
                                                                            const std::uint32_t* sub_index,
                                                                            std::span<const PointXYZI> points,
                                                                            std::size_t first) const;
  // decide_lanes for the AVX2 scan: out of line (inlined, the scan's loop reloaded its
  // constants from the stack: 16 ymm registers are few), compiled for AVX2 (so that no SSE
  // code runs with the upper vector state dirty).
  __attribute__((target("avx2"), noinline)) unsigned decide_lanes_avx2(unsigned boundary,
                                                                       const std::uint32_t* sub_index,
                                                                       std::span<const PointXYZI> points,
                                                                       std::size_t first) const;
#endif

  // 0/1: is the point (x, y) in a cell with this value kept? Tests candidates for boundary cells.
  // Inlined into each scan (GCC takes always_inline from this declaration, not from the
  // definition in grid_filter_scan.hpp): called out of line from a vector scan, every call
  // spilled and reloaded the scan's vector registers around it.
  [[nodiscard]] __attribute__((always_inline)) inline std::uint32_t decide(std::uint32_t cell, double x,
                                                                           double y) const noexcept;
  // The same for the point's sub-cell value in a boundary cell.
  [[nodiscard]] __attribute__((always_inline)) inline std::uint32_t decide_sub(std::uint32_t sub, double x,
                                                                               double y) const noexcept;
  // Index into cells_ of the cell holding (x, y); the sentinel when off the grid.
  [[nodiscard]] std::size_t cell_index(float x, float y) const noexcept;

  static inline std::atomic<SimdPath> auto_path_{SimdPath::kAuto};  // set by calibrate()
  const RoiSet* rois_ = nullptr;
  float x0_ = 0.0f;  // grid origin (global frame, m)
  float y0_ = 0.0f;
  float inv_cell_ = 1.0f;  // 1 / cell size (1/m)
  double cell_size_m_ = 1.0;
  std::size_t nx_ = 0;
  std::size_t ny_ = 0;
  std::vector<std::uint32_t> cells_;
  // Sub-cells per side of a boundary cell.
  static constexpr std::uint32_t kSub = 4;
  std::vector<std::uint32_t> sub_;                              // boundary id · kSub² + sub-cell → value
  std::vector<std::uint32_t> sub_offsets_;                      // sub-boundary id → [first, last) candidate
  std::vector<std::uint32_t> sub_candidates_;                   // ROI indices, nearest first
  std::vector<std::uint32_t> offsets_;                          // build scratch: boundary cell → candidates
  std::vector<std::uint32_t> candidates_;                       // build scratch
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_;  // build scratch: (cell, roi)
  std::vector<std::uint32_t> cursor_;                           // build scratch
  std::vector<std::pair<double, double>> roi_centre_;           // build scratch
};

#undef TRAJROI_STANDARD_CALL

extern template class GridFilter<CircularRoiSet>;
extern template class GridFilter<RectangularRoiSet>;
extern template class GridFilter<CorridorRoiSet>;

}  // namespace trajroi::roi
