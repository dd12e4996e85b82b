// The grid filter's build, its calibration and its filter entry (which runs the scan chosen at
// run time: grid_filter_sse2.cpp, grid_filter_avx2.cpp, grid_filter_avx512.cpp, or the scalar
// code of grid_filter_scan.hpp), instantiated for the three ROI shapes and both point types.
// Kept out of the public header so that <immintrin.h> and the scans stay in roi/src.
#include "trajroi/roi/grid_filter.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>

#include "grid_filter_scan.hpp"

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
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
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
  // The paths are timed in rounds, one run of each per round in a rotating order, each keeping
  // its fastest: a slow spell of the machine (another process, a frequency change) then falls
  // on every path alike instead of on whichever was being timed, and cannot make a narrower
  // scan look faster than a wider one it only happened to follow.
  std::vector<SimdPath> paths;
  for (const SimdPath path : {SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar})
    if (cpu_has(path)) paths.push_back(path);
  std::vector<double> fastest(paths.size(), std::numeric_limits<double>::infinity());
  std::vector<bool> out_of_it(paths.size(), false);
  for (std::size_t round = 0; round < 7; ++round) {
    for (std::size_t k = 0; k < paths.size(); ++k) {
      const std::size_t i = (k + round) % paths.size();
      if (out_of_it[i]) continue;
      const auto start = std::chrono::steady_clock::now();
      (void)filter(points, kept, paths[i]);
      const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
      fastest[i] = std::min(fastest[i], ns / static_cast<double>(points.size()));
    }
    // Twice as slow as the best path even at its second run: it cannot win (start-up is part
    // of a replay's time).
    const double best_so_far = *std::min_element(fastest.begin(), fastest.end());
    for (std::size_t i = 0; i < paths.size() && round >= 1; ++i)
      out_of_it[i] = out_of_it[i] || fastest[i] > 2.0 * best_so_far;
  }
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < paths.size(); ++i) {
    result.ns_per_point[static_cast<int>(paths[i])] = fastest[i];
    // A narrower scan must be clearly faster (3 %) to be chosen over a wider one.
    if (fastest[i] < best * 0.97) {
      best = fastest[i];
      result.chosen = paths[i];
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
    if (wide && cpu_has(SimdPath::kAvx512)) {
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

// Not inlined into the vector scans (their registers stay theirs): defined and instantiated here.
template <typename RoiSet>
std::size_t GridFilter<RoiSet>::scalar_block(std::span<const PointXYZI> points, std::size_t first, std::size_t n,
                                             Scan& scan, std::size_t count) const {
  scan.count = count;
  for (std::size_t k = first; k < first + n; ++k)
    scalar_point(points, k, scan);
  return scan.count;
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
