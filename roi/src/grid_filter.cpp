// The grid filter's build and its per-point scans (scalar, SSE2, AVX2, AVX-512; the widest the
// CPU has is chosen at run time), instantiated for the three ROI shapes and both point types.
// Kept out of the header so that <immintrin.h> and the scans stay in this file.
#include "trajroi/roi/grid_filter.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace trajroi::roi {

const char* to_string(SimdPath path) noexcept {
  switch (path) {
    case SimdPath::kAvx512:
      return "avx512";
    case SimdPath::kAvx2:
      return "avx2";
    case SimdPath::kSse2:
      return "sse2";
    case SimdPath::kScalar:
      return "scalar";
    case SimdPath::kAuto:
      break;
  }
  return "auto";
}

bool simd_path_from_string(const char* text, SimdPath& path) noexcept {
  for (const SimdPath p : {SimdPath::kAuto, SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
    if (std::strcmp(text, to_string(p)) == 0) {
      path = p;
      return true;
    }
  }
  if (*text != '\0') return false;
  path = SimdPath::kAuto;
  return true;
}

bool cpu_has(SimdPath path) noexcept {
#if defined(__x86_64__) || defined(__i386__)
  switch (path) {
    case SimdPath::kAvx512:
      return __builtin_cpu_supports("avx512f");
    case SimdPath::kAvx2:
      return __builtin_cpu_supports("avx2");
    case SimdPath::kSse2:
      return true;  // every x86-64
    case SimdPath::kScalar:
    case SimdPath::kAuto:
      return true;
  }
  return false;
#else
  return path == SimdPath::kScalar || path == SimdPath::kAuto;
#endif
}

template <typename RoiSet>
SimdPath GridFilter<RoiSet>::auto_path() noexcept {
  return auto_path_.load(std::memory_order_relaxed);
}

template <typename RoiSet>
ScanCalibration GridFilter<RoiSet>::calibrate() const {
  ScanCalibration result;
  if (rois_ == nullptr) return result;  // not built: nothing to time on
  if (const char* forced = std::getenv("TRAJROI_SIMD"); forced != nullptr && *forced != '\0') {
    SimdPath path = SimdPath::kAuto;
    if (simd_path_from_string(forced, path) && path != SimdPath::kAuto) {
      result.chosen = path;
      result.forced = true;
      auto_path_.store(path, std::memory_order_relaxed);
      return result;
    }
  }
  // A LiDAR-like cloud over the grid, in firing order: 16 lasers on rings about the grid's
  // centre, 0.2° apart in azimuth, so consecutive firings mostly land in the same cells as
  // real sweeps do (what the scans' cell reuse is for); the rings reach the grid's corners.
  const double h = cell_size_m_;
  const double cx = static_cast<double>(x0_) + 0.5 * h * static_cast<double>(nx_);
  const double cy = static_cast<double>(y0_) + 0.5 * h * static_cast<double>(ny_);
  const double reach = 0.5 * h * std::hypot(static_cast<double>(nx_), static_cast<double>(ny_));
  // A height every point passes: between the z limits, at one that is set, or 0.
  const ZLimits& limits = rois_->z_limits();
  const double lo = std::isfinite(limits.min_m) ? limits.min_m : std::min(0.0, limits.max_m);
  const double hi = std::isfinite(limits.max_m) ? limits.max_m : std::max(lo, 0.0);
  const double z = 0.5 * (lo + hi);
  constexpr std::size_t kFirings = 1800;  // one turn
  constexpr std::size_t kLasers = 16;
  std::vector<PointXYZI> cloud;
  cloud.reserve(kFirings * kLasers);
  for (std::size_t f = 0; f < kFirings; ++f) {
    const double azimuth = 2.0 * std::numbers::pi * static_cast<double>(f) / static_cast<double>(kFirings);
    const double cos_a = std::cos(azimuth);  // once per firing: start-up is part of a replay's time
    const double sin_a = std::sin(azimuth);
    for (std::size_t l = 0; l < kLasers; ++l) {
      const double ring = reach * static_cast<double>(l + 1) / static_cast<double>(kLasers);
      const double r = ring * (1.0 + 0.05 * std::sin(7.0 * azimuth + static_cast<double>(l)));
      cloud.push_back(
          {static_cast<float>(cx + r * cos_a), static_cast<float>(cy + r * sin_a), static_cast<float>(z), 0.0f});
    }
  }
  IndexVector kept;
  kept.reserve(cloud.size());
  const std::span<const PointXYZI> points(cloud);
  double best = std::numeric_limits<double>::infinity();
  for (const SimdPath path : {SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
    if (!cpu_has(path)) continue;
    double fastest = std::numeric_limits<double>::infinity();
    for (int run = 0; run < 7; ++run) {
      const auto start = std::chrono::steady_clock::now();
      (void)filter(points, kept, path);
      const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
      fastest = std::min(fastest, ns / static_cast<double>(points.size()));
      // Twice as slow as the best path so far even at its second run: it cannot win (start-up
      // is part of a replay's time).
      if (run >= 1 && fastest > 2.0 * best) break;
    }
    result.ns_per_point[static_cast<int>(path)] = fastest;
    // A narrower scan must be clearly faster (3 %) to be chosen over a wider one.
    if (fastest < best * 0.97) {
      best = fastest;
      result.chosen = path;
    }
  }
  auto_path_.store(result.chosen, std::memory_order_relaxed);
  return result;
}

template <typename RoiSet>
void GridFilter<RoiSet>::build(const RoiSet& rois) {
  rois_ = &rois;
  cells_.clear();
  offsets_.clear();
  candidates_.clear();
  pairs_.clear();
  nx_ = ny_ = 0;
  const std::size_t m = rois.size();
  if (m == 0) {  // no point is on a 0 × 0 grid: all read the sentinel
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
  const double magnitude = std::max({std::abs(bb.x_min), std::abs(bb.x_max), std::abs(bb.y_min), std::abs(bb.y_max),
                                     bb.x_max - bb.x_min, bb.y_max - bb.y_min, 1.0});
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
    while (std::ceil(width / h) * std::ceil(height / h) > static_cast<double>(kMaxCells))
      h *= 1.01;
  }
  // The float origin and scale filter() uses define the grid; classification uses the same
  // values widened to double, so both describe the same cells up to float rounding.
  x0_ = float_at_or_below(bb.x_min);
  y0_ = float_at_or_below(bb.y_min);
  inv_cell_ = static_cast<float>(1.0 / h);
  h = 1.0 / static_cast<double>(inv_cell_);
  cell_size_m_ = h;
  nx_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil((bb.x_max - static_cast<double>(x0_)) / h)));
  ny_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil((bb.y_max - static_cast<double>(y0_)) / h)));
  cells_.assign(nx_ * ny_ + 1, kOutside);  // + the sentinel cell for off-grid points

  auto cell_at = [](double v, float origin, float inv, std::size_t n) {
    const double f = std::floor((v - static_cast<double>(origin)) * static_cast<double>(inv));
    if (!(f > 0.0)) return std::size_t{0};
    return std::min(static_cast<std::size_t>(f), n - 1);
  };
  const double x0 = static_cast<double>(x0_);
  const double y0 = static_cast<double>(y0_);
  for (std::size_t j = 0; j < m; ++j) {
    const Box b = rois.bounds(j);
    const double reach = tolerance + cell_pad;
    const std::size_t ix0 = cell_at(b.x_min - reach, x0_, inv_cell_, nx_);
    const std::size_t ix1 = cell_at(b.x_max + reach, x0_, inv_cell_, nx_);
    const std::size_t iy0 = cell_at(b.y_min - reach, y0_, inv_cell_, ny_);
    const std::size_t iy1 = cell_at(b.y_max + reach, y0_, inv_cell_, ny_);
    for (std::size_t iy = iy0; iy <= iy1; ++iy) {
      for (std::size_t ix = ix0; ix <= ix1; ++ix) {
        const std::size_t c = iy * nx_ + ix;
        if (cells_[c] == kInside) continue;
        const Box cell{x0 + static_cast<double>(ix) * h - cell_pad, y0 + static_cast<double>(iy) * h - cell_pad,
                       x0 + static_cast<double>(ix + 1) * h + cell_pad,
                       y0 + static_cast<double>(iy + 1) * h + cell_pad};
        switch (rois.relation(j, cell, tolerance)) {
          case CellRelation::kInside:
            cells_[c] = kInside;
            break;
          case CellRelation::kBoundary:
            pairs_.emplace_back(static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(j));
            break;
          case CellRelation::kOutside:
            break;
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
  for (std::uint32_t id = 0; id < boundary; ++id)
    offsets_[id + 1] = offsets_[id] + cursor_[id];
  std::copy(offsets_.begin(), offsets_.end() - 1, cursor_.begin());
  candidates_.resize(offsets_.back());
  for (const auto& [c, j] : pairs_) {
    if (cells_[c] == kInside) continue;
    candidates_[cursor_[cells_[c] - kFirstBoundary]++] = j;
  }
  // Nearest ROI first (by the centre of its bounds): a point inside the chain usually stops
  // at the first test. The decision is an OR over the list, so the order cannot change it.
  roi_centre_.clear();
  for (std::size_t j = 0; j < m; ++j) {
    const Box b = rois.bounds(j);
    roi_centre_.emplace_back(0.5 * (b.x_min + b.x_max), 0.5 * (b.y_min + b.y_max));
  }
  for (std::size_t c = 0; c < nx_ * ny_; ++c) {
    if (cells_[c] < kFirstBoundary) continue;
    const std::uint32_t id = cells_[c] - kFirstBoundary;
    const double mx = x0 + (static_cast<double>(c % nx_) + 0.5) * h;
    const double my = y0 + (static_cast<double>(c / nx_) + 0.5) * h;
    auto distance2 = [&](std::uint32_t j) {
      const double dx = roi_centre_[j].first - mx;
      const double dy = roi_centre_[j].second - my;
      return dx * dx + dy * dy;
    };
    std::sort(candidates_.begin() + offsets_[id], candidates_.begin() + offsets_[id + 1],
              [&](std::uint32_t a, std::uint32_t b) { return distance2(a) < distance2(b); });
  }

  // Second level: each boundary cell is split into kSub × kSub sub-cells, classified against
  // the cell's candidates with the same margins. Only points in boundary sub-cells run
  // candidate tests, against the sub-cell's shorter list (still nearest first).
  const double hs = h / kSub;
  sub_.assign(static_cast<std::size_t>(boundary) * kSub * kSub, kOutside);
  sub_offsets_.assign(1, 0);
  sub_candidates_.clear();
  for (std::size_t c = 0; c < nx_ * ny_; ++c) {
    if (cells_[c] < kFirstBoundary) continue;
    const std::uint32_t id = cells_[c] - kFirstBoundary;
    const double cx0 = x0 + static_cast<double>(c % nx_) * h;
    const double cy0 = y0 + static_cast<double>(c / nx_) * h;
    for (std::uint32_t sy = 0; sy < kSub; ++sy) {
      for (std::uint32_t sx = 0; sx < kSub; ++sx) {
        const Box sub{cx0 + sx * hs - cell_pad, cy0 + sy * hs - cell_pad, cx0 + (sx + 1) * hs + cell_pad,
                      cy0 + (sy + 1) * hs + cell_pad};
        const std::size_t first = sub_candidates_.size();
        std::uint32_t value = kOutside;
        for (std::uint32_t k = offsets_[id]; k < offsets_[id + 1]; ++k) {
          const CellRelation relation = rois.relation(candidates_[k], sub, tolerance);
          if (relation == CellRelation::kInside) {
            value = kInside;
            break;
          }
          if (relation == CellRelation::kBoundary) sub_candidates_.push_back(candidates_[k]);
        }
        if (value == kInside) {
          sub_candidates_.resize(first);
        } else if (sub_candidates_.size() > first) {
          value = kFirstBoundary + static_cast<std::uint32_t>(sub_offsets_.size() - 1);
          sub_offsets_.push_back(static_cast<std::uint32_t>(sub_candidates_.size()));
        }
        sub_[static_cast<std::size_t>(id) * kSub * kSub + sy * kSub + sx] = value;
      }
    }
  }
}

template <typename RoiSet>
__attribute__((always_inline)) inline std::uint32_t GridFilter<RoiSet>::decide(std::uint32_t cell, double x,
                                                                               double y) const noexcept {
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
__attribute__((always_inline)) inline std::uint32_t GridFilter<RoiSet>::decide_sub(std::uint32_t sub, double x,
                                                                                   double y) const noexcept {
  if (sub < kFirstBoundary) return sub;
  const std::uint32_t id = sub - kFirstBoundary;
  for (std::uint32_t k = sub_offsets_[id]; k < sub_offsets_[id + 1]; ++k) {
    if (rois_->contains(sub_candidates_[k], x, y)) return 1;
  }
  return 0;
}

template <typename RoiSet>
template <typename Point>
void GridFilter<RoiSet>::scalar_point(std::span<const Point> points, std::size_t i, Scan& scan) const {
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
template <typename Point>
FilterStats GridFilter<RoiSet>::filter(std::span<const Point> points, IndexVector& kept,
                                       [[maybe_unused]] SimdPath path) const {
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
    if (path == SimdPath::kAuto) path = auto_path_.load(std::memory_order_relaxed);
    const bool wide = path == SimdPath::kAuto || path == SimdPath::kAvx512;
    if (wide && __builtin_cpu_supports("avx512f")) {
      i = scan_avx512(points, scan);
    } else if ((wide || path == SimdPath::kAvx2) && __builtin_cpu_supports("avx2")) {
      i = scan_avx2(points, scan);
    } else if (path != SimdPath::kScalar) {
      i = scan_sse2(points, scan);
    }
#endif
  }
  for (; i < points.size(); ++i)
    scalar_point(points, i, scan);
  kept.resize(scan.count);
  stats.kept = scan.count;
  return stats;
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

template <typename RoiSet>
std::size_t GridFilter<RoiSet>::scan_sse2(std::span<const PointXYZI> points, Scan& scan) const {
  static_assert(sizeof(PointXYZI) == 16);
  if (points.size() < 4) return 0;
  const FloatZLimits z = float_z_limits(rois_->z_limits());
  const bool z_limited = z.limited;
  const __m128 lo = _mm_set1_ps(z.lo);
  const __m128 hi = _mm_set1_ps(z.hi);
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
  const std::size_t ahead = detail::prefetch_distance(points);
  std::size_t i = 0;
  for (; i + 4 <= points.size(); i += 4) {
    detail::prefetch_ahead<4 * sizeof(PointXYZI)>(base + 4 * i, ahead);
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
      count = scalar_block(points, i, 4, scan, count);
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
        count += decide(c[k], static_cast<double>(points[i + k].x), static_cast<double>(points[i + k].y));
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

template <typename RoiSet>
std::size_t GridFilter<RoiSet>::scalar_block(std::span<const PointXYZI> points, std::size_t first, std::size_t n,
                                             Scan& scan, std::size_t count) const {
  scan.count = count;
  for (std::size_t k = first; k < first + n; ++k)
    scalar_point(points, k, scan);
  return scan.count;
}

template <typename RoiSet>
inline unsigned GridFilter<RoiSet>::decide_lanes(unsigned boundary, const std::uint32_t* sub_index,
                                                 std::span<const PointXYZI> points, std::size_t first) const {
  unsigned keep = 0;
  for (; boundary != 0; boundary &= boundary - 1) {
    const auto k = static_cast<unsigned>(__builtin_ctz(boundary));
    keep |= decide_sub(sub_[sub_index[k]], static_cast<double>(points[first + k].x),
                       static_cast<double>(points[first + k].y))
            << k;
  }
  return keep;
}

template <typename RoiSet>
unsigned GridFilter<RoiSet>::decide_lanes_avx2(unsigned boundary, const std::uint32_t* sub_index,
                                               std::span<const PointXYZI> points, std::size_t first) const {
  return decide_lanes(boundary, sub_index, points, first);
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

namespace detail {
// What the AVX2 scan needs to locate eight points' cells.
struct Avx2Grid {
  __m256 x0, y0, inv, nx_f, ny_f, z_lo, z_hi;
  __m256i nx_i, sentinel;
  bool z_limited;
  const int* cells;
};

// The cells (indices into the cell table) of the eight points at `p` (x, y, z, intensity
// each), in point order, the sentinel for off-grid points; `clean` is false when one of them
// is non-finite or outside the z limits.
struct Avx2Block {
  __m256i cell;
  bool clean;
};

// The x, y and z of the eight points at `p`, in lane order 0 2 4 6 1 3 5 7 (what the
// transposition gives), and their grid coordinates in cells.
struct Avx2Points {
  __m256 x, y, z;
  __m256 fx, fy;
};

__attribute__((target("avx2"), always_inline)) inline Avx2Points avx2_points(const float* p, const Avx2Grid& g) {
  const __m256 a = _mm256_loadu_ps(p);         // points 0, 1
  const __m256 b = _mm256_loadu_ps(p + 8);     // points 2, 3
  const __m256 c = _mm256_loadu_ps(p + 16);    // points 4, 5
  const __m256 d = _mm256_loadu_ps(p + 24);    // points 6, 7
  const __m256 t0 = _mm256_unpacklo_ps(a, b);  // x0 x2 y0 y2 | x1 x3 y1 y3
  const __m256 t1 = _mm256_unpackhi_ps(a, b);  // z0 z2 . .   | z1 z3 . .
  const __m256 t2 = _mm256_unpacklo_ps(c, d);
  const __m256 t3 = _mm256_unpackhi_ps(c, d);
  const __m256 px = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));  // x 0 2 4 6 | 1 3 5 7
  const __m256 py = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
  const __m256 pz = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
  return {px, py, pz, _mm256_mul_ps(_mm256_sub_ps(px, g.x0), g.inv), _mm256_mul_ps(_mm256_sub_ps(py, g.y0), g.inv)};
}

// The transposition's lane order put back to point order.
__attribute__((target("avx2"), always_inline)) inline __m256i avx2_natural(__m256i v) {
  return _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7));
}

__attribute__((target("avx2"), always_inline)) inline Avx2Block avx2_block(const float* p, const Avx2Grid& g) {
  const auto [px, py, pz, fx, fy] = avx2_points(p, g);
  // v − v is 0 for every finite v and NaN for ±∞ and NaN: the sum is 0 when all three are finite.
  const __m256 zero = _mm256_setzero_ps();
  const __m256 finite_sum =
      _mm256_add_ps(_mm256_add_ps(_mm256_sub_ps(px, px), _mm256_sub_ps(py, py)), _mm256_sub_ps(pz, pz));
  __m256 pass = _mm256_cmp_ps(finite_sum, zero, _CMP_EQ_OQ);
  if (g.z_limited) {
    pass = _mm256_and_ps(pass,
                         _mm256_and_ps(_mm256_cmp_ps(pz, g.z_lo, _CMP_GE_OQ), _mm256_cmp_ps(pz, g.z_hi, _CMP_LE_OQ)));
  }
  // fx ≥ 0 and fy ≥ 0 as min(fx, fy) ≥ 0 (a NaN, from a non-finite point, makes the block unclean).
  const __m256 on_grid =
      _mm256_and_ps(_mm256_cmp_ps(_mm256_min_ps(fx, fy), zero, _CMP_GE_OQ),
                    _mm256_and_ps(_mm256_cmp_ps(fx, g.nx_f, _CMP_LT_OQ), _mm256_cmp_ps(fy, g.ny_f, _CMP_LT_OQ)));
  // Off-grid lanes are zeroed before converting; on-grid values are ≥ 0 (truncation floors).
  const __m256i ix = _mm256_cvttps_epi32(_mm256_and_ps(fx, on_grid));
  const __m256i iy = _mm256_cvttps_epi32(_mm256_and_ps(fy, on_grid));
  const __m256i cell = _mm256_blendv_epi8(g.sentinel, _mm256_add_epi32(_mm256_mullo_epi32(iy, g.nx_i), ix),
                                          _mm256_castps_si256(on_grid));
  return {avx2_natural(cell), _mm256_movemask_ps(pass) == 0xff};
}

// A LiDAR cloud in firing order brings the same laser back every block or two, and its
// consecutive returns mostly land in the same cell: the scans keep the cells and values of
// an earlier block and gather only the lanes whose cell has changed (none, most of the
// time). Any order gives the same result; this one only makes it cheaper.
struct Avx2Reuse {
  __m256i cell;
  __m256i value;  // the cell table's entries for `cell`
};

__attribute__((target("avx2"), always_inline)) inline __m256i avx2_values(__m256i cell, Avx2Reuse& reuse,
                                                                          const int* cells) {
  const __m256i same = _mm256_cmpeq_epi32(cell, reuse.cell);
  if (_mm256_movemask_ps(_mm256_castsi256_ps(same)) != 0xff) {
    reuse.value =
        _mm256_mask_i32gather_epi32(reuse.value, cells, cell, _mm256_xor_si256(same, _mm256_set1_epi32(-1)), 4);
    reuse.cell = cell;
  }
  return reuse.value;
}

// Writes the indices first … first + 7 whose bit is set in `keep` to out, packed; returns
// how many. Writes eight slots at `out`.
__attribute__((target("avx2,popcnt"), always_inline)) inline std::size_t avx2_emit(unsigned keep, std::size_t first,
                                                                                   std::uint32_t* out) {
  const __m256i indices =
      _mm256_add_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(first)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  const __m256i packed =
      _mm256_permutevar8x32_epi32(indices, _mm256_load_si256(reinterpret_cast<const __m256i*>(kCompress.lanes[keep])));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), packed);
  return static_cast<std::size_t>(__builtin_popcount(keep));
}

// Lane masks of the values equal to 1 (inside) and above 1 (boundary ids).
__attribute__((target("avx2"), always_inline)) inline unsigned avx2_inside(__m256i value) {
  return static_cast<unsigned>(
      _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(value, _mm256_set1_epi32(1)))));
}
__attribute__((target("avx2"), always_inline)) inline unsigned avx2_boundary(__m256i value) {
  return static_cast<unsigned>(
      _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(value, _mm256_set1_epi32(1)))));
}

__attribute__((target("avx2"), always_inline)) inline void avx2_store(__m256i value, std::uint32_t* out) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), value);
}

// As avx512_sub_index, for the eight points at `p` with cell values `cell_value` (in point
// order): the indices into GridFilter::sub_ of their sub-cells, meaningful in the boundary
// lanes only. Their grid coordinates are located again (avx2_points, as in avx2_block): this
// runs for one block in seven or so, and keeping them from avx2_block would cost the main
// loop registers it does not have.
template <std::uint32_t kSub, std::uint32_t kFirstBoundary>
__attribute__((target("avx2"), always_inline)) inline __m256i avx2_sub_index(const float* p, const Avx2Grid& g,
                                                                             __m256i cell_value) {
  const Avx2Points at = avx2_points(p, g);
  const __m256 per_side = _mm256_set1_ps(static_cast<float>(kSub));
  const __m256i last = _mm256_set1_epi32(static_cast<std::int32_t>(kSub - 1));
  const __m256 frac_x = _mm256_sub_ps(at.fx, _mm256_cvtepi32_ps(_mm256_cvttps_epi32(at.fx)));
  const __m256 frac_y = _mm256_sub_ps(at.fy, _mm256_cvtepi32_ps(_mm256_cvttps_epi32(at.fy)));
  const __m256i sx = avx2_natural(_mm256_min_epu32(_mm256_cvttps_epi32(_mm256_mul_ps(frac_x, per_side)), last));
  const __m256i sy = avx2_natural(_mm256_min_epu32(_mm256_cvttps_epi32(_mm256_mul_ps(frac_y, per_side)), last));
  // ((cell value − first boundary value) · kSub + sy) · kSub + sx
  const __m256i side = _mm256_set1_epi32(static_cast<std::int32_t>(kSub));
  const __m256i id = _mm256_sub_epi32(cell_value, _mm256_set1_epi32(kFirstBoundary));
  return _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(_mm256_mullo_epi32(id, side), sy), side), sx);
}
}  // namespace detail

template <typename RoiSet>
__attribute__((target("avx2,popcnt"))) std::size_t GridFilter<RoiSet>::scan_avx2(std::span<const PointXYZI> points,
                                                                                 Scan& scan) const {
  if (points.size() < 8) return 0;
  const FloatZLimits z = float_z_limits(rois_->z_limits());
  const detail::Avx2Grid grid{_mm256_set1_ps(x0_),
                              _mm256_set1_ps(y0_),
                              _mm256_set1_ps(inv_cell_),
                              _mm256_set1_ps(static_cast<float>(nx_)),
                              _mm256_set1_ps(static_cast<float>(ny_)),
                              _mm256_set1_ps(z.lo),
                              _mm256_set1_ps(z.hi),
                              _mm256_set1_epi32(static_cast<std::int32_t>(nx_)),
                              _mm256_set1_epi32(static_cast<std::int32_t>(cells_.size() - 1)),
                              z.limited,
                              reinterpret_cast<const int*>(cells_.data())};
  const float* const base = &points.data()->x;
  std::uint32_t* const out = scan.out;
  std::size_t count = scan.count;
  // Keeps the block's inside points and those of its boundary points a candidate ROI
  // accepts, in order. A block with a point to reject goes to the scalar code, which counts
  // why. Since count ≤ first, an 8-slot store at out + count stays within first + 8 ≤ n.
  auto finish = [&](std::size_t first, const detail::Avx2Block& block, detail::Avx2Reuse& reuse)
      __attribute__((target("avx2,popcnt"))) {
    if (!block.clean) [[unlikely]] {
      count = scalar_block(points, first, 8, scan, count);
      return;
    }
    const __m256i value = detail::avx2_values(block.cell, reuse, grid.cells);
    unsigned keep = detail::avx2_inside(value);
    if (const unsigned boundary = detail::avx2_boundary(value); boundary != 0) [[unlikely]] {
      // Their sub-cells, located all at once; only points in boundary sub-cells test candidates.
      alignas(32) std::uint32_t sub_index[8];
      detail::avx2_store(detail::avx2_sub_index<kSub, kFirstBoundary>(base + 4 * first, grid, value), sub_index);
      keep |= decide_lanes_avx2(boundary, sub_index, points, first);
    }
    count += detail::avx2_emit(keep, first, out + count);
  };
  // Two blocks per step (the first and second half of a VLP-16 firing), each reusing the
  // values of the same half one step earlier. All reused cells start as the sentinel.
  detail::Avx2Reuse first_half{grid.sentinel, _mm256_setzero_si256()};
  detail::Avx2Reuse second_half = first_half;
  const std::size_t ahead = detail::prefetch_distance(points);
  std::size_t i = 0;
  for (; i + 16 <= points.size(); i += 16) {
    detail::prefetch_ahead<16 * sizeof(PointXYZI)>(base + 4 * i, ahead);
    const detail::Avx2Block a = detail::avx2_block(base + 4 * i, grid);
    const detail::Avx2Block b = detail::avx2_block(base + 4 * (i + 8), grid);
    finish(i, a, first_half);
    finish(i + 8, b, second_half);
  }
  for (; i + 8 <= points.size(); i += 8)
    finish(i, detail::avx2_block(base + 4 * i, grid), first_half);
  scan.count = count;
  return i;
}

namespace detail {
// What the AVX-512 scan needs to locate sixteen points' cells.
struct Avx512Grid {
  __m512 x0, y0, inv, nx_f, ny_f, z_lo, z_hi;
  __m512i nx_i, sentinel;
  bool z_limited;
  const int* cells;
};

// As Avx2Block, for sixteen points, with their grid coordinates in cells (whose fractions
// give the sub-cells of the points in boundary cells).
struct Avx512Block {
  __m512i cell;
  __m512 fx;
  __m512 fy;
  bool clean;
};

__attribute__((target("avx512f"), always_inline)) inline Avx512Block avx512_block(const float* p, const Avx512Grid& g) {
  const __m512 a = _mm512_loadu_ps(p);       // points 0–3
  const __m512 b = _mm512_loadu_ps(p + 16);  // points 4–7
  const __m512 c = _mm512_loadu_ps(p + 32);  // points 8–11
  const __m512 d = _mm512_loadu_ps(p + 48);  // points 12–15
  // x of eight points in lanes 0–7 and their y in lanes 8–15; then z (and intensity).
  const __m512i xy = _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 1, 5, 9, 13, 17, 21, 25, 29);
  const __m512i zw = _mm512_setr_epi32(2, 6, 10, 14, 18, 22, 26, 30, 3, 7, 11, 15, 19, 23, 27, 31);
  const __m512 xy_ab = _mm512_permutex2var_ps(a, xy, b);
  const __m512 xy_cd = _mm512_permutex2var_ps(c, xy, d);
  const __m512 zw_ab = _mm512_permutex2var_ps(a, zw, b);
  const __m512 zw_cd = _mm512_permutex2var_ps(c, zw, d);
  const __m512i low = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23);
  const __m512i high = _mm512_add_epi32(low, _mm512_set1_epi32(8));
  const __m512 px = _mm512_permutex2var_ps(xy_ab, low, xy_cd);
  const __m512 py = _mm512_permutex2var_ps(xy_ab, high, xy_cd);
  const __m512 pz = _mm512_permutex2var_ps(zw_ab, low, zw_cd);
  const __m512 max_finite = _mm512_set1_ps(std::numeric_limits<float>::max());
  __mmask16 pass = _mm512_cmp_ps_mask(_mm512_abs_ps(px), max_finite, _CMP_LE_OQ) &
                   _mm512_cmp_ps_mask(_mm512_abs_ps(py), max_finite, _CMP_LE_OQ) &
                   _mm512_cmp_ps_mask(_mm512_abs_ps(pz), max_finite, _CMP_LE_OQ);
  if (g.z_limited) {
    pass = _mm512_kand(
        pass, _mm512_kand(_mm512_cmp_ps_mask(pz, g.z_lo, _CMP_GE_OQ), _mm512_cmp_ps_mask(pz, g.z_hi, _CMP_LE_OQ)));
  }
  const __m512 zero = _mm512_setzero_ps();
  const __m512 fx = _mm512_mul_ps(_mm512_sub_ps(px, g.x0), g.inv);
  const __m512 fy = _mm512_mul_ps(_mm512_sub_ps(py, g.y0), g.inv);
  const __mmask16 on_grid = _mm512_cmp_ps_mask(fx, zero, _CMP_GE_OQ) & _mm512_cmp_ps_mask(fx, g.nx_f, _CMP_LT_OQ) &
                            _mm512_cmp_ps_mask(fy, zero, _CMP_GE_OQ) & _mm512_cmp_ps_mask(fy, g.ny_f, _CMP_LT_OQ);
  // On-grid values are ≥ 0 (truncation floors).
  const __m512i ix = _mm512_maskz_cvttps_epi32(on_grid, fx);
  const __m512i iy = _mm512_maskz_cvttps_epi32(on_grid, fy);
  const __m512i cell = _mm512_add_epi32(_mm512_mullo_epi32(iy, g.nx_i), ix);
  return {_mm512_mask_blend_epi32(on_grid, g.sentinel, cell), fx, fy, pass == 0xffff};
}

// The indices into GridFilter::sub_ of the sub-cells of the lanes of `boundary` (0 in the
// others), from the same float operations as GridFilter::decide(), so every path picks the
// same sub-cell. (Gathering their values in one 16-lane gather was slower than loading the
// few that the boundary lanes need.)
template <std::uint32_t kSub, std::uint32_t kFirstBoundary>
__attribute__((target("avx512f"), always_inline)) inline __m512i avx512_sub_index(__mmask16 boundary,
                                                                                  const Avx512Block& block,
                                                                                  __m512i cell_value) {
  // Masked forms throughout: only the boundary lanes matter (and GCC 12 warns of the
  // unmasked forms' undefined source).
  const __mmask16 m = boundary;
  const __m512 per_side = _mm512_set1_ps(static_cast<float>(kSub));
  const __m512i last = _mm512_set1_epi32(static_cast<std::int32_t>(kSub - 1));
  const __m512 frac_x = _mm512_sub_ps(block.fx, _mm512_maskz_cvtepi32_ps(m, _mm512_maskz_cvttps_epi32(m, block.fx)));
  const __m512 frac_y = _mm512_sub_ps(block.fy, _mm512_maskz_cvtepi32_ps(m, _mm512_maskz_cvttps_epi32(m, block.fy)));
  const __m512i sx = _mm512_maskz_min_epu32(m, _mm512_maskz_cvttps_epi32(m, _mm512_mul_ps(frac_x, per_side)), last);
  const __m512i sy = _mm512_maskz_min_epu32(m, _mm512_maskz_cvttps_epi32(m, _mm512_mul_ps(frac_y, per_side)), last);
  // ((cell value − first boundary value) · kSub + sy) · kSub + sx
  const __m512i side = _mm512_set1_epi32(static_cast<std::int32_t>(kSub));
  const __m512i id = _mm512_maskz_sub_epi32(m, cell_value, _mm512_set1_epi32(kFirstBoundary));
  return _mm512_add_epi32(_mm512_mullo_epi32(_mm512_add_epi32(_mm512_mullo_epi32(id, side), sy), side), sx);
}

// As Avx2Reuse: the cells and values of the previous block (one VLP-16 firing earlier).
struct Avx512Reuse {
  __m512i cell;
  __m512i value;
};

__attribute__((target("avx512f"), always_inline)) inline __m512i avx512_values(__m512i cell, Avx512Reuse& reuse,
                                                                               const int* cells) {
  const __mmask16 changed = _mm512_cmpneq_epi32_mask(cell, reuse.cell);
  if (changed != 0) {
    reuse.value = _mm512_mask_i32gather_epi32(reuse.value, changed, cell, cells, 4);
    reuse.cell = cell;
  }
  return reuse.value;
}
}  // namespace detail

template <typename RoiSet>
__attribute__((target("avx512f,popcnt"))) std::size_t GridFilter<RoiSet>::scan_avx512(std::span<const PointXYZI> points,
                                                                                      Scan& scan) const {
  if (points.size() < 16) return 0;
  const FloatZLimits z = float_z_limits(rois_->z_limits());
  const detail::Avx512Grid grid{_mm512_set1_ps(x0_),
                                _mm512_set1_ps(y0_),
                                _mm512_set1_ps(inv_cell_),
                                _mm512_set1_ps(static_cast<float>(nx_)),
                                _mm512_set1_ps(static_cast<float>(ny_)),
                                _mm512_set1_ps(z.lo),
                                _mm512_set1_ps(z.hi),
                                _mm512_set1_epi32(static_cast<std::int32_t>(nx_)),
                                _mm512_set1_epi32(static_cast<std::int32_t>(cells_.size() - 1)),
                                z.limited,
                                reinterpret_cast<const int*>(cells_.data())};
  const float* const base = &points.data()->x;
  std::uint32_t* const out = scan.out;
  std::size_t count = scan.count;
  detail::Avx512Reuse reuse{grid.sentinel, _mm512_setzero_si512()};  // the sentinel reads 0
  const __m512i one = _mm512_set1_epi32(1);
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  // Keeps the block's inside points and those of its boundary points that a candidate ROI
  // accepts, in order. A block with a point to reject goes to the scalar code, which counts
  // why. Since count ≤ first, a 16-slot store at out + count stays within first + 16 ≤ n.
  auto finish = [&](std::size_t first, const detail::Avx512Block& block) __attribute__((target("avx512f,popcnt"))) {
    if (!block.clean) [[unlikely]] {
      count = scalar_block(points, first, 16, scan, count);
      return;
    }
    const __m512i cell_value = detail::avx512_values(block.cell, reuse, grid.cells);
    auto keep = static_cast<unsigned>(_mm512_cmpeq_epi32_mask(cell_value, one));
    if (const __mmask16 boundary = _mm512_cmpgt_epu32_mask(cell_value, one); boundary != 0) [[unlikely]] {
      // Their sub-cells, located all at once; only points in boundary sub-cells test candidates.
      alignas(64) std::uint32_t sub_index[16];
      _mm512_store_si512(sub_index, detail::avx512_sub_index<kSub, kFirstBoundary>(boundary, block, cell_value));
      keep |= decide_lanes(boundary, sub_index, points, first);
    }
    const __m512i indices = _mm512_add_epi32(_mm512_set1_epi32(static_cast<std::int32_t>(first)), lane);
    _mm512_storeu_si512(out + count, _mm512_maskz_compress_epi32(static_cast<__mmask16>(keep), indices));
    count += static_cast<std::size_t>(__builtin_popcount(keep));
  };
  // Two blocks per step: both are located before either is looked up.
  const std::size_t ahead = detail::prefetch_distance(points);
  std::size_t i = 0;
  for (; i + 32 <= points.size(); i += 32) {
    detail::prefetch_ahead<32 * sizeof(PointXYZI)>(base + 4 * i, ahead);
    const detail::Avx512Block a = detail::avx512_block(base + 4 * i, grid);
    const detail::Avx512Block b = detail::avx512_block(base + 4 * (i + 16), grid);
    finish(i, a);
    finish(i + 16, b);
  }
  for (; i + 16 <= points.size(); i += 16)
    finish(i, detail::avx512_block(base + 4 * i, grid));
  scan.count = count;
  return i;
}
#endif  // x86

template <typename RoiSet>
std::size_t GridFilter<RoiSet>::cell_index(float x, float y) const noexcept {
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

template class GridFilter<CircularRoiSet>;
template class GridFilter<RectangularRoiSet>;
template class GridFilter<CorridorRoiSet>;

#define TRAJROI_GRID_FILTER_POINTS(RoiSet)                                                                       \
  template FilterStats GridFilter<RoiSet>::filter<PointXYZI>(std::span<const PointXYZI>, IndexVector&, SimdPath) \
      const;                                                                                                     \
  template FilterStats GridFilter<RoiSet>::filter<PointXYZd>(std::span<const PointXYZd>, IndexVector&, SimdPath) const;
TRAJROI_GRID_FILTER_POINTS(CircularRoiSet)
TRAJROI_GRID_FILTER_POINTS(RectangularRoiSet)
TRAJROI_GRID_FILTER_POINTS(CorridorRoiSet)
#undef TRAJROI_GRID_FILTER_POINTS

}  // namespace trajroi::roi
