#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "trajroi/roi/filter_stats.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::roi {

enum class SimdPath : unsigned char { kAuto, kAvx2, kSse2, kScalar };

// The float nearest to v on the given side (v itself when exactly representable).
[[nodiscard]] inline float float_at_or_below(double v) noexcept {
  const auto f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
[[nodiscard]] inline float float_at_or_above(double v) noexcept {
  const auto f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// The fast filter: the same membership decision as reference_filter for every point, bit for
// bit, at a per-point cost that does not grow with the number of ROIs.
//
// build() lays a uniform grid over the chain's bounding box and classifies every cell, with a
// margin far larger than rounding error, as outside every ROI, inside at least one ROI, or
// boundary. A boundary cell keeps the ascending list of ROIs that may contain some of its
// points; a point in such a cell is decided by calling the same RoiSet::contains() the
// reference calls, on those candidates only. Since every ROI left out of the list rejects
// the point for sure, and any ROI that accepts it makes the reference keep it, both agree.
//
// A filter() call allocates nothing once `kept` has the capacity; build() reuses its storage.
template <typename RoiSet>
class GridFilter {
 public:
  // Cell count ceiling: 4 M cells (16 MiB); a larger area gets coarser cells, still exact.
  static constexpr std::size_t kMaxCells = std::size_t{1} << 22;

  // `rois` must stay alive and unchanged until the next build().
  void build(const RoiSet& rois);

  // `path` chooses the implementation of the per-point scan for PointXYZI clouds (other point
  // types always take the scalar path); every path gives the same result. kAuto takes the
  // widest the CPU supports; the others exist so tests can check each one.
  template <typename Point>
  FilterStats filter(std::span<const Point> points, IndexVector& kept,
                     SimdPath path = SimdPath::kAuto) const;

  [[nodiscard]] std::size_t cell_count() const noexcept { return nx_ * ny_; }
  [[nodiscard]] std::size_t boundary_cell_count() const noexcept {
    return offsets_.empty() ? 0 : offsets_.size() - 1;
  }
  [[nodiscard]] double cell_size_m() const noexcept { return cell_size_m_; }

 private:
  static constexpr std::uint32_t kOutside = 0;
  static constexpr std::uint32_t kInside = 1;
  static constexpr std::uint32_t kFirstBoundary = 2;  // cell value = boundary id + 2

  struct Scan {
    std::uint32_t* out;   // room for every point
    std::size_t count;    // indices written so far
    FilterStats* stats;
  };
  template <typename Point>
  void scalar_point(std::span<const Point> points, std::size_t i, Scan& scan) const;
#if defined(__x86_64__) || defined(__i386__)
  std::size_t scan_sse2(std::span<const PointXYZI> points, Scan& scan) const;
  __attribute__((target("avx2,popcnt"))) std::size_t scan_avx2(std::span<const PointXYZI> points,
                                                               Scan& scan) const;
#endif

  // 0/1: is the point (x, y) in a cell with this value kept? Tests candidates for boundary cells.
  [[nodiscard]] std::uint32_t decide(std::uint32_t cell, double x, double y) const noexcept;
  // Index into cells_ of the cell holding (x, y); the sentinel when off the grid.
  [[nodiscard]] std::size_t cell_index(float x, float y) const noexcept;

  const RoiSet* rois_ = nullptr;
  float x0_ = 0.0f;        // grid origin (global frame, m)
  float y0_ = 0.0f;
  float inv_cell_ = 1.0f;  // 1 / cell size (1/m)
  double cell_size_m_ = 1.0;
  std::size_t nx_ = 0;
  std::size_t ny_ = 0;
  std::vector<std::uint32_t> cells_;
  std::vector<std::uint32_t> offsets_;     // boundary id → [offsets_[id], offsets_[id + 1])
  std::vector<std::uint32_t> candidates_;  // ROI indices, nearest first within one cell
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_;  // build scratch: (cell, roi)
  std::vector<std::uint32_t> cursor_;                            // build scratch
};

template <typename RoiSet>
void GridFilter<RoiSet>::build(const RoiSet& rois) {
  rois_ = &rois;
  cells_.clear();
  offsets_.clear();
  candidates_.clear();
  pairs_.clear();
  nx_ = ny_ = 0;
  const std::size_t m = rois.size();
  if (m == 0) {
    nx_ = ny_ = 0;  // no point is on a 0 × 0 grid: all read the sentinel
    cells_.assign(1, kOutside);
    return;
  }

  Box bb = rois.bounds(0);
  for (std::size_t j = 1; j < m; ++j) {
    const Box b = rois.bounds(j);
    bb = {std::min(bb.x_min, b.x_min), std::min(bb.y_min, b.y_min), std::max(bb.x_max, b.x_max),
          std::max(bb.y_max, b.y_max)};
  }
  // Rounding in the per-point tests and in locating a point's cell is a few ulps of the
  // coordinates' magnitude; a margin of 1e-9 of that magnitude dwarfs it, and at 1 nm for
  // local coordinates it changes no classification that matters.
  const double magnitude = std::max({std::abs(bb.x_min), std::abs(bb.x_max), std::abs(bb.y_min),
                                     std::abs(bb.y_max), bb.x_max - bb.x_min, bb.y_max - bb.y_min,
                                     1.0});
  const double tolerance = 1e-9 * magnitude;
  // filter() locates a point's cell in float (a few float roundings, < 3e-7 of the magnitude):
  // every cell is classified as if it were larger by this pad, so a point the float
  // arithmetic puts in a neighbouring cell is still covered by that cell's classification.
  const double cell_pad = 1e-6 * magnitude;
  bb = {bb.x_min - cell_pad, bb.y_min - cell_pad, bb.x_max + cell_pad, bb.y_max + cell_pad};
  const double width = bb.x_max - bb.x_min + 1.0;  // + room for the float origin below
  const double height = bb.y_max - bb.y_min + 1.0;

  double h = rois.cell_size_hint_m();
  if (std::ceil(width / h) * std::ceil(height / h) > static_cast<double>(kMaxCells)) {
    h = std::sqrt(width * height / static_cast<double>(kMaxCells)) * 1.01;
    while (std::ceil(width / h) * std::ceil(height / h) > static_cast<double>(kMaxCells)) h *= 1.01;
  }
  cell_size_m_ = h;
  // The float origin and scale filter() uses define the grid; classification uses the same
  // values widened to double, so both describe the same cells up to float rounding.
  x0_ = float_at_or_below(bb.x_min);
  y0_ = float_at_or_below(bb.y_min);
  inv_cell_ = static_cast<float>(1.0 / h);
  h = 1.0 / static_cast<double>(inv_cell_);
  cell_size_m_ = h;
  nx_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil((bb.x_max - static_cast<double>(x0_)) / h)));
  ny_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil((bb.y_max - static_cast<double>(y0_)) / h)));
  if (nx_ * ny_ > kMaxCells + (nx_ + ny_)) nx_ = ny_ = 1;  // unreachable; keeps the bound obvious
  cells_.assign(nx_ * ny_ + 1, kOutside);  // + the sentinel cell for off-grid points

  auto cell_index = [](double v, float origin, float inv, std::size_t n) {
    const double f = std::floor((v - static_cast<double>(origin)) * static_cast<double>(inv));
    if (!(f > 0.0)) return std::size_t{0};
    return std::min(static_cast<std::size_t>(f), n - 1);
  };
  const double x0 = static_cast<double>(x0_);
  const double y0 = static_cast<double>(y0_);
  for (std::size_t j = 0; j < m; ++j) {
    const Box b = rois.bounds(j);
    const double reach = tolerance + cell_pad;
    const std::size_t ix0 = cell_index(b.x_min - reach, x0_, inv_cell_, nx_);
    const std::size_t ix1 = cell_index(b.x_max + reach, x0_, inv_cell_, nx_);
    const std::size_t iy0 = cell_index(b.y_min - reach, y0_, inv_cell_, ny_);
    const std::size_t iy1 = cell_index(b.y_max + reach, y0_, inv_cell_, ny_);
    for (std::size_t iy = iy0; iy <= iy1; ++iy) {
      for (std::size_t ix = ix0; ix <= ix1; ++ix) {
        const std::size_t c = iy * nx_ + ix;
        if (cells_[c] == kInside) continue;
        const Box cell{x0 + static_cast<double>(ix) * h - cell_pad,
                       y0 + static_cast<double>(iy) * h - cell_pad,
                       x0 + static_cast<double>(ix + 1) * h + cell_pad,
                       y0 + static_cast<double>(iy + 1) * h + cell_pad};
        switch (rois.relation(j, cell, tolerance)) {
          case CellRelation::kInside: cells_[c] = kInside; break;
          case CellRelation::kBoundary:
            pairs_.emplace_back(static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(j));
            break;
          case CellRelation::kOutside: break;
        }
      }
    }
  }

  // Number the boundary cells (those not made inside by some ROI) and gather their
  // candidates.
  std::uint32_t boundary = 0;
  cursor_.clear();
  for (const auto& [c, j] : pairs_) {
    if (cells_[c] == kInside) continue;
    if (cells_[c] == kOutside) {
      cells_[c] = kFirstBoundary + boundary++;
      cursor_.push_back(0);
    }
    ++cursor_[cells_[c] - kFirstBoundary];
  }
  offsets_.assign(boundary + 1, 0);
  for (std::uint32_t id = 0; id < boundary; ++id) offsets_[id + 1] = offsets_[id] + cursor_[id];
  std::copy(offsets_.begin(), offsets_.end() - 1, cursor_.begin());
  candidates_.resize(offsets_.back());
  for (const auto& [c, j] : pairs_) {
    if (cells_[c] == kInside) continue;
    candidates_[cursor_[cells_[c] - kFirstBoundary]++] = j;
  }
  // Nearest ROI first (by the centre of its bounds): a point inside the chain usually stops
  // at the first test. The decision is an OR over the list, so the order cannot change it.
  for (std::size_t c = 0; c < nx_ * ny_; ++c) {
    if (cells_[c] < kFirstBoundary) continue;
    const std::uint32_t id = cells_[c] - kFirstBoundary;
    const double mx = x0 + (static_cast<double>(c % nx_) + 0.5) * h;
    const double my = y0 + (static_cast<double>(c / nx_) + 0.5) * h;
    auto distance2 = [&](std::uint32_t j) {
      const Box b = rois.bounds(j);
      const double dx = 0.5 * (b.x_min + b.x_max) - mx;
      const double dy = 0.5 * (b.y_min + b.y_max) - my;
      return dx * dx + dy * dy;
    };
    std::sort(candidates_.begin() + offsets_[id], candidates_.begin() + offsets_[id + 1],
              [&](std::uint32_t a, std::uint32_t b) { return distance2(a) < distance2(b); });
  }
}

template <typename RoiSet>
std::uint32_t GridFilter<RoiSet>::decide(std::uint32_t cell, double x, double y) const noexcept {
  if (cell < kFirstBoundary) return cell;  // kOutside = 0, kInside = 1
  const std::uint32_t id = cell - kFirstBoundary;
  for (std::uint32_t k = offsets_[id]; k < offsets_[id + 1]; ++k) {
    if (rois_->contains(candidates_[k], x, y)) return 1;
  }
  return 0;
}

template <typename RoiSet>
template <typename Point>
void GridFilter<RoiSet>::scalar_point(std::span<const Point> points, std::size_t i,
                                      Scan& scan) const {
  const double x = points[i].x;
  const double y = points[i].y;
  const double z = points[i].z;
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
template <typename Point>
FilterStats GridFilter<RoiSet>::filter(std::span<const Point> points, IndexVector& kept,
                                       SimdPath path) const {
  FilterStats stats;
  stats.input = points.size();
  kept.clear();
  if (rois_ == nullptr) return stats;
  // Every index is written and the count advances by the 0/1 decision, so the output needs
  // room for all points; IndexVector's resize() does not zero it.
  kept.resize(points.size());
  Scan scan{kept.data(), 0, &stats};
  std::size_t i = 0;
  if constexpr (std::is_same_v<Point, PointXYZI>) {
#if defined(__x86_64__) || defined(__i386__)
    if ((path == SimdPath::kAuto || path == SimdPath::kAvx2) && __builtin_cpu_supports("avx2")) {
      i = scan_avx2(points, scan);
    } else if (path != SimdPath::kScalar) {
      i = scan_sse2(points, scan);
    }
#endif
  }
  for (; i < points.size(); ++i) scalar_point(points, i, scan);
  kept.resize(scan.count);
  stats.kept = scan.count;
  return stats;
}

// Vector scans over PointXYZI clouds. A PointXYZI is exactly one 16-byte vector (x, y, z,
// intensity); the scans compute the cell of each point with the same float operations as
// cell_index(), so every path assigns every point the same cell. A block in which a point is
// non-finite or outside the z limits, or lies in a boundary cell, is handed to the scalar
// code point by point. Both return the index of the first point they did not process.
#if defined(__x86_64__) || defined(__i386__)
template <typename RoiSet>
std::size_t GridFilter<RoiSet>::scan_sse2(std::span<const PointXYZI> points, Scan& scan) const {
  static_assert(sizeof(PointXYZI) == 16);
  if (points.size() < 4) return 0;
  const ZLimits& z_limits = rois_->z_limits();
  const bool z_limited = std::isfinite(z_limits.min_m) || std::isfinite(z_limits.max_m);
  const __m128 lo = _mm_set1_ps(float_at_or_above(std::max(z_limits.min_m, -double{std::numeric_limits<float>::max()})));
  const __m128 hi = _mm_set1_ps(float_at_or_below(std::min(z_limits.max_m, double{std::numeric_limits<float>::max()})));
  const __m128 x0 = _mm_set1_ps(x0_);
  const __m128 y0 = _mm_set1_ps(y0_);
  const __m128 inv = _mm_set1_ps(inv_cell_);
  const __m128 nx_f = _mm_set1_ps(static_cast<float>(nx_));
  const __m128 ny_f = _mm_set1_ps(static_cast<float>(ny_));
  const __m128 zero = _mm_setzero_ps();
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 max_finite = _mm_set1_ps(std::numeric_limits<float>::max());
  const __m128i sentinel = _mm_set1_epi32(static_cast<std::int32_t>(cells_.size() - 1));
  const std::uint32_t* const cells = cells_.data();
  const float* const base = &points.data()->x;
  std::uint32_t* const out = scan.out;
  std::size_t count = scan.count;
  alignas(16) std::int32_t cell_of[4];
  std::size_t i = 0;
  for (; i + 4 <= points.size(); i += 4) {
    __m128 px = _mm_loadu_ps(base + 4 * i);
    __m128 py = _mm_loadu_ps(base + 4 * i + 4);
    __m128 pz = _mm_loadu_ps(base + 4 * i + 8);
    __m128 pi = _mm_loadu_ps(base + 4 * i + 12);
    _MM_TRANSPOSE4_PS(px, py, pz, pi);  // → x, y, z, intensity of the four points
    __m128 pass = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(_mm_and_ps(px, abs_mask), max_finite),
                                        _mm_cmple_ps(_mm_and_ps(py, abs_mask), max_finite)),
                             _mm_cmple_ps(_mm_and_ps(pz, abs_mask), max_finite));
    if (z_limited) pass = _mm_and_ps(pass, _mm_and_ps(_mm_cmpge_ps(pz, lo), _mm_cmple_ps(pz, hi)));
    if (_mm_movemask_ps(pass) != 0xf) [[unlikely]] {
      scan.count = count;
      for (std::size_t k = i; k < i + 4; ++k) scalar_point(points, k, scan);
      count = scan.count;
      continue;
    }
    const __m128 fx = _mm_mul_ps(_mm_sub_ps(px, x0), inv);
    const __m128 fy = _mm_mul_ps(_mm_sub_ps(py, y0), inv);
    const __m128 on_grid = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(fx, zero), _mm_cmplt_ps(fx, nx_f)),
                                      _mm_and_ps(_mm_cmpge_ps(fy, zero), _mm_cmplt_ps(fy, ny_f)));
    // Off-grid lanes are zeroed before converting; on-grid values are ≥ 0, so truncation is
    // the floor, and iy · nx + ix < kMaxCells < 2^24 is exact in float.
    const __m128 ixf = _mm_cvtepi32_ps(_mm_cvttps_epi32(_mm_and_ps(fx, on_grid)));
    const __m128 iyf = _mm_cvtepi32_ps(_mm_cvttps_epi32(_mm_and_ps(fy, on_grid)));
    const __m128i cell = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(iyf, nx_f), ixf));
    const __m128i grid_mask = _mm_castps_si128(on_grid);
    _mm_store_si128(reinterpret_cast<__m128i*>(cell_of),
                    _mm_or_si128(_mm_and_si128(grid_mask, cell), _mm_andnot_si128(grid_mask, sentinel)));
    const std::uint32_t c0 = cells[cell_of[0]];
    const std::uint32_t c1 = cells[cell_of[1]];
    const std::uint32_t c2 = cells[cell_of[2]];
    const std::uint32_t c3 = cells[cell_of[3]];
    if ((c0 | c1 | c2 | c3) >= kFirstBoundary) [[unlikely]] {
      const std::uint32_t c[4] = {c0, c1, c2, c3};
      for (std::size_t k = 0; k < 4; ++k) {
        out[count] = static_cast<std::uint32_t>(i + k);
        count += decide(c[k], points[i + k].x, points[i + k].y);
      }
      continue;
    }
    out[count] = static_cast<std::uint32_t>(i);
    count += c0;
    out[count] = static_cast<std::uint32_t>(i + 1);
    count += c1;
    out[count] = static_cast<std::uint32_t>(i + 2);
    count += c2;
    out[count] = static_cast<std::uint32_t>(i + 3);
    count += c3;
  }
  scan.count = count;
  return i;
}

namespace detail {
// For each 8-bit keep mask, the lanes to keep, packed to the front: compaction by one
// permutevar8x32.
struct CompressTable {
  alignas(32) std::uint32_t lanes[256][8];
  constexpr CompressTable() : lanes{} {
    for (unsigned mask = 0; mask < 256; ++mask) {
      unsigned n = 0;
      for (unsigned lane = 0; lane < 8; ++lane) {
        if ((mask >> lane) & 1u) lanes[mask][n++] = lane;
      }
    }
  }
};
inline constexpr CompressTable kCompress{};
}  // namespace detail

template <typename RoiSet>
__attribute__((target("avx2,popcnt"))) std::size_t GridFilter<RoiSet>::scan_avx2(
    std::span<const PointXYZI> points, Scan& scan) const {
  if (points.size() < 8) return 0;
  const ZLimits& z_limits = rois_->z_limits();
  const bool z_limited = std::isfinite(z_limits.min_m) || std::isfinite(z_limits.max_m);
  const __m256 lo = _mm256_set1_ps(float_at_or_above(std::max(z_limits.min_m, -double{std::numeric_limits<float>::max()})));
  const __m256 hi = _mm256_set1_ps(float_at_or_below(std::min(z_limits.max_m, double{std::numeric_limits<float>::max()})));
  const __m256 x0 = _mm256_set1_ps(x0_);
  const __m256 y0 = _mm256_set1_ps(y0_);
  const __m256 inv = _mm256_set1_ps(inv_cell_);
  const __m256 nx_f = _mm256_set1_ps(static_cast<float>(nx_));
  const __m256 ny_f = _mm256_set1_ps(static_cast<float>(ny_));
  const __m256i nx_i = _mm256_set1_epi32(static_cast<std::int32_t>(nx_));
  const __m256 zero = _mm256_setzero_ps();
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256 max_finite = _mm256_set1_ps(std::numeric_limits<float>::max());
  const __m256i sentinel = _mm256_set1_epi32(static_cast<std::int32_t>(cells_.size() - 1));
  const __m256i one = _mm256_set1_epi32(1);
  // The transposition below leaves points in lane order 0 2 4 6 1 3 5 7; this puts them back.
  const __m256i natural = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
  const __m256i lane_offset = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const auto* const cells = reinterpret_cast<const int*>(cells_.data());
  const float* const base = &points.data()->x;
  std::uint32_t* const out = scan.out;
  std::size_t count = scan.count;
  alignas(32) std::uint32_t cell_value[8];
  std::size_t i = 0;
  for (; i + 8 <= points.size(); i += 8) {
    const __m256 a = _mm256_loadu_ps(base + 4 * i);       // points 0, 1
    const __m256 b = _mm256_loadu_ps(base + 4 * i + 8);   // points 2, 3
    const __m256 c = _mm256_loadu_ps(base + 4 * i + 16);  // points 4, 5
    const __m256 d = _mm256_loadu_ps(base + 4 * i + 24);  // points 6, 7
    const __m256 t0 = _mm256_unpacklo_ps(a, b);           // x0 x2 y0 y2 | x1 x3 y1 y3
    const __m256 t1 = _mm256_unpackhi_ps(a, b);           // z0 z2 . .   | z1 z3 . .
    const __m256 t2 = _mm256_unpacklo_ps(c, d);
    const __m256 t3 = _mm256_unpackhi_ps(c, d);
    const __m256 px = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));  // x 0 2 4 6 | 1 3 5 7
    const __m256 py = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    const __m256 pz = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    __m256 pass = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps(_mm256_and_ps(px, abs_mask), max_finite, _CMP_LE_OQ),
                      _mm256_cmp_ps(_mm256_and_ps(py, abs_mask), max_finite, _CMP_LE_OQ)),
        _mm256_cmp_ps(_mm256_and_ps(pz, abs_mask), max_finite, _CMP_LE_OQ));
    if (z_limited) {
      pass = _mm256_and_ps(pass, _mm256_and_ps(_mm256_cmp_ps(pz, lo, _CMP_GE_OQ),
                                               _mm256_cmp_ps(pz, hi, _CMP_LE_OQ)));
    }
    if (_mm256_movemask_ps(pass) != 0xff) [[unlikely]] {
      scan.count = count;
      for (std::size_t k = i; k < i + 8; ++k) scalar_point(points, k, scan);
      count = scan.count;
      continue;
    }
    const __m256 fx = _mm256_mul_ps(_mm256_sub_ps(px, x0), inv);
    const __m256 fy = _mm256_mul_ps(_mm256_sub_ps(py, y0), inv);
    const __m256 on_grid = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps(fx, zero, _CMP_GE_OQ), _mm256_cmp_ps(fx, nx_f, _CMP_LT_OQ)),
        _mm256_and_ps(_mm256_cmp_ps(fy, zero, _CMP_GE_OQ), _mm256_cmp_ps(fy, ny_f, _CMP_LT_OQ)));
    const __m256i ix = _mm256_cvttps_epi32(_mm256_and_ps(fx, on_grid));
    const __m256i iy = _mm256_cvttps_epi32(_mm256_and_ps(fy, on_grid));
    const __m256i cell = _mm256_blendv_epi8(sentinel, _mm256_add_epi32(_mm256_mullo_epi32(iy, nx_i), ix),
                                            _mm256_castps_si256(on_grid));
    const __m256i value = _mm256_i32gather_epi32(cells, _mm256_permutevar8x32_epi32(cell, natural), 4);
    if (_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(value, one))) != 0) [[unlikely]] {
      _mm256_store_si256(reinterpret_cast<__m256i*>(cell_value), value);
      for (std::size_t k = 0; k < 8; ++k) {
        out[count] = static_cast<std::uint32_t>(i + k);
        count += decide(cell_value[k], points[i + k].x, points[i + k].y);
      }
      continue;
    }
    const auto keep = static_cast<unsigned>(
        _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(value, one))));
    // count ≤ i, so the 8-lane store stays inside the first i + 8 ≤ n slots of `out`.
    const __m256i indices = _mm256_add_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(i)), lane_offset);
    const __m256i packed = _mm256_permutevar8x32_epi32(
        indices, _mm256_load_si256(reinterpret_cast<const __m256i*>(detail::kCompress.lanes[keep])));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + count), packed);
    count += static_cast<std::size_t>(__builtin_popcount(keep));
  }
  scan.count = count;
  return i;
}
#endif  // x86

template <typename RoiSet>
std::size_t GridFilter<RoiSet>::cell_index(float x, float y) const noexcept {
  // The same float operations as the SSE2 path: identical cells on either path.
  const float fx = (x - x0_) * inv_cell_;
  const float fy = (y - y0_) * inv_cell_;
  const bool on_grid = fx >= 0.0f && fx < static_cast<float>(nx_) && fy >= 0.0f &&
                       fy < static_cast<float>(ny_);  // false for NaN
  if (!on_grid) return cells_.size() - 1;
  const auto ix = static_cast<float>(static_cast<std::int32_t>(fx));
  const auto iy = static_cast<float>(static_cast<std::int32_t>(fy));
  return static_cast<std::size_t>(static_cast<std::int32_t>(iy * static_cast<float>(nx_) + ix));
}

}  // namespace trajroi::roi
