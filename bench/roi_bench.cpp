// ROI membership speed: the paper's double loop (reference) against the grid filter (fast),
// and the physical limits of touching the same points (a streaming read and a memcpy).
//
// Names: roi/<circular|rectangular>/<reference|fast>/<frame|accumulated>/<25|10>
//        limit/<read|memcpy>/<frame|accumulated>
// Each fast iteration rebuilds the grid, as the daemon does for every sweep.
// The fast filter runs the scan GridFilter::calibrate() found fastest on this machine for each
// shape (as the daemon does at start); TRAJROI_SIMD=avx512|avx2|sse2|scalar forces one, to
// compare them. The context printed first names the CPU, the cores and each shape's scan with
// the calibration's times. probe/clock and probe/scan (the scan of one frame in the cache) measure
// the core between the others: their ranges show a slow spell of the host during the run.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#include "machine_context.hpp"
#include "synthetic_cloud.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/reference_filter.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::bench {
namespace {

// Paper parameters: circle diameter 6 m; rectangle a = 3 m along, b = 6 m across.
constexpr double kDiameter_m = 6.0;
constexpr double kRectHeight_m = 3.0;
constexpr double kRectWidth_m = 6.0;

const std::vector<roi::PointXYZI>& cloud(bool accumulated) {
  static const std::vector<roi::PointXYZI> frame = [] {
    // the single frame seen in the global frame at the start of the trajectory
    std::vector<roi::PointXYZI> f = synthetic_frame();
    roi::transform_points(roi::pose_from_xy_yaw(0.0, 0.0, 0.0, kSensorHeight_m), f, f);
    return f;
  }();
  static const std::vector<roi::PointXYZI> many = accumulated_cloud(100);
  return accumulated ? many : frame;
}

// A bad TRAJROI_SIMD stops the benchmark before any run.
void check_simd_variable() {
  const char* name = std::getenv("TRAJROI_SIMD");
  roi::SimdPath path = roi::SimdPath::kAuto;
  if (name != nullptr && !roi::simd_path_from_string(name, path)) {
    std::fprintf(stderr, "roi_bench: TRAJROI_SIMD=%s is not auto, avx512, avx2, sse2 or scalar\n", name);
    std::exit(2);
  }
}

const roi::Trajectory& trajectory() {
  static const roi::Trajectory t = synthetic_trajectory();
  return t;
}

template <typename RoiSet>
RoiSet make_set(int ratio_pct);

template <>
roi::CircularRoiSet make_set<roi::CircularRoiSet>(int ratio_pct) {
  std::vector<roi::Centre> centres;
  roi::place_centres(trajectory(), 0.0, std::numeric_limits<double>::infinity(),
                     roi::spacing_from_ratio(ratio_pct / 100.0, kDiameter_m), centres);
  return roi::CircularRoiSet(kDiameter_m / 2.0, centres);
}

template <>
roi::RectangularRoiSet make_set<roi::RectangularRoiSet>(int ratio_pct) {
  std::vector<roi::Centre> centres;
  roi::place_centres(trajectory(), 0.0, std::numeric_limits<double>::infinity(),
                     roi::spacing_from_ratio(ratio_pct / 100.0, kRectHeight_m), centres);
  return roi::RectangularRoiSet(kRectHeight_m, kRectWidth_m, centres);
}

void set_counters(benchmark::State& state, std::size_t points, std::size_t kept, std::size_t rois) {
  const auto n = static_cast<std::int64_t>(points);
  state.SetItemsProcessed(state.iterations() * n);
  state.SetBytesProcessed(state.iterations() * n * static_cast<std::int64_t>(sizeof(roi::PointXYZI)));
  state.counters["points"] = static_cast<double>(points);
  state.counters["kept_fraction"] = static_cast<double>(kept) / static_cast<double>(points);
  state.counters["rois"] = static_cast<double>(rois);
}

template <typename RoiSet>
void reference(benchmark::State& state, bool accumulated, int ratio_pct) {
  const auto& points = cloud(accumulated);
  const RoiSet set = make_set<RoiSet>(ratio_pct);
  roi::IndexVector kept;
  kept.reserve(points.size());
  for (auto _ : state) {
    roi::reference_filter(set, std::span<const roi::PointXYZI>(points), kept);
    benchmark::DoNotOptimize(kept.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, points.size(), kept.size(), set.size());
}

template <typename RoiSet>
void fast(benchmark::State& state, bool accumulated, int ratio_pct) {
  const auto& points = cloud(accumulated);
  const RoiSet set = make_set<RoiSet>(ratio_pct);
  roi::GridFilter<RoiSet> grid;
  roi::IndexVector kept;
  kept.reserve(points.size());
  for (auto _ : state) {
    grid.build(set);
    grid.filter(std::span<const roi::PointXYZI>(points), kept);
    benchmark::DoNotOptimize(kept.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, points.size(), kept.size(), set.size());
  state.counters["cells"] = static_cast<double>(grid.cell_count());
  state.counters["boundary_cells"] = static_cast<double>(grid.boundary_cell_count());
}

void limit_read(benchmark::State& state, bool accumulated) {
  const auto& points = cloud(accumulated);
  for (auto _ : state) {
    float sum = 0.0f;
    for (const roi::PointXYZI& p : points)
      sum += p.x + p.y + p.z;
    benchmark::DoNotOptimize(sum);
  }
  set_counters(state, points.size(), 0, 0);
}

void limit_memcpy(benchmark::State& state, bool accumulated) {
  const auto& points = cloud(accumulated);
  std::vector<roi::PointXYZI> copy(points.size());
  for (auto _ : state) {
    std::memcpy(copy.data(), points.data(), points.size() * sizeof(roi::PointXYZI));
    benchmark::DoNotOptimize(copy.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, points.size(), 0, 0);
}

// The fast filter's scan alone on one frame held in the cache, on a grid built once (rectangles,
// 10 %): bound by the core, not by memory. Its range over a run shows whether the host slowed the
// core's vector work meanwhile, which the integer clock (probe/clock) does not always show.
constexpr int kProbePasses = 10;
void probe_scan(benchmark::State& state) {
  const auto& points = cloud(false);
  const auto set = make_set<roi::RectangularRoiSet>(10);
  roi::GridFilter<roi::RectangularRoiSet> grid;
  grid.build(set);
  roi::IndexVector kept;
  kept.reserve(points.size());
  for (auto _ : state) {
    for (int pass = 0; pass < kProbePasses; ++pass) {
      grid.filter(std::span<const roi::PointXYZI>(points), kept);
      benchmark::DoNotOptimize(kept.data());
    }
  }
  set_counters(state, points.size() * kProbePasses, kept.size() * kProbePasses, set.size());
}

// Calibrates the shape's scan on its 25 % chain (what the daemon does at start) and says the
// choice in the benchmark's context.
template <typename RoiSet>
void calibrate(const char* shape) {
  const RoiSet set = make_set<RoiSet>(25);
  roi::GridFilter<RoiSet> grid;
  grid.build(set);
  benchmark::AddCustomContext(std::string("scan_") + shape, roi::describe(grid.calibrate()));
}

int register_all() {
  check_simd_variable();
  calibrate<roi::CircularRoiSet>("circular");
  calibrate<roi::RectangularRoiSet>("rectangular");
  register_core_clock();
  with_range(benchmark::RegisterBenchmark("probe/scan", probe_scan))->Unit(benchmark::kMicrosecond);
  for (const bool accumulated : {false, true}) {
    const std::string where = accumulated ? "accumulated" : "frame";
    const auto unit = accumulated ? benchmark::kMillisecond : benchmark::kMicrosecond;
    for (const int ratio : {25, 10}) {
      const std::string r = std::to_string(ratio);
      benchmark::RegisterBenchmark(("roi/circular/reference/" + where + "/" + r).c_str(),
                                   reference<roi::CircularRoiSet>, accumulated, ratio)
          ->Unit(unit);
      benchmark::RegisterBenchmark(("roi/circular/fast/" + where + "/" + r).c_str(), fast<roi::CircularRoiSet>,
                                   accumulated, ratio)
          ->Unit(unit);
      benchmark::RegisterBenchmark(("roi/rectangular/reference/" + where + "/" + r).c_str(),
                                   reference<roi::RectangularRoiSet>, accumulated, ratio)
          ->Unit(unit);
      benchmark::RegisterBenchmark(("roi/rectangular/fast/" + where + "/" + r).c_str(), fast<roi::RectangularRoiSet>,
                                   accumulated, ratio)
          ->Unit(unit);
    }
    benchmark::RegisterBenchmark(("limit/read/" + where).c_str(), limit_read, accumulated)->Unit(unit);
    benchmark::RegisterBenchmark(("limit/memcpy/" + where).c_str(), limit_memcpy, accumulated)->Unit(unit);
  }
  return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace trajroi::bench

BENCHMARK_MAIN();
