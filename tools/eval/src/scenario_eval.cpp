// The paper's scenario evaluations on a run: the keyframes (Tables 9, 11), the sequential
// frames (Table 18) and the accumulated clouds (Table 19).
#include "trajroi/eval/scenario_eval.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "timing.hpp"
#include "trajroi/config/text_file.hpp"
#include "trajroi/inputs/capture.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/transform.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::eval {
namespace fs = std::filesystem;

// ---- keyframes ----------------------------------------------------------------------------

std::vector<KeyframeCase> keyframe_cases(const ScenarioRun& run, PoseMode mode) {
  const auto& keyframes = run.scenario().evaluation.keyframes;
  std::vector<KeyframeCase> cases(keyframes.size());
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    const sim::Keyframe& kf = keyframes[k];
    double best = std::numeric_limits<double>::infinity();
    for (const sim::TruePose& p : run.truth().poses()) {
      if (std::cos(p.yaw_rad - kf.heading_rad) <= 0.0) continue;  // the other direction
      const double d = std::hypot(p.x_m - kf.position_m.x(), p.y_m - kf.position_m.y());
      if (d < best) {
        best = d;
        cases[k].time_ns = p.t_ns;
      }
    }
    if (!(best <= 1.0)) {
      throw std::runtime_error(run.dir().string() + ": keyframe '" + kf.name + "' is " +
                               (std::isfinite(best) ? std::to_string(best) + " m" : std::string("far")) +
                               " from the robot's path");
    }
    cases[k].keyframe = kf;
  }
  std::vector<std::uint8_t> found(cases.size(), 0);
  run.for_each_frame([&](const vlp16::Frame& frame, std::uint64_t, double) {
    if (frame.partial) return;
    for (std::size_t k = 0; k < cases.size(); ++k) {
      if (found[k] == 0 && frame.start_time_ns <= cases[k].time_ns && cases[k].time_ns < frame.end_time_ns) {
        cases[k].frame = frame;
        cases[k].frame_index = frame.index;
        found[k] = 1;
      }
    }
  });
  std::int64_t last_end = std::numeric_limits<std::int64_t>::min();
  for (std::size_t k = 0; k < cases.size(); ++k) {
    if (found[k] == 0)
      throw std::runtime_error(run.dir().string() + ": no complete frame at keyframe '" + cases[k].keyframe.name + "'");
    last_end = std::max(last_end, cases[k].frame.end_time_ns);
  }
  // The keyframes' sweeps through the daemon's pipeline: their points as it places them, the
  // robot's projection where it starts the chain.
  struct Collect final : PipelineObserver {
    std::vector<KeyframeCase>* cases;
    std::vector<std::uint8_t> placed_ok;
    std::vector<pose::PoseStatus> status;
    void on_placed(std::size_t, const vlp16::Frame& frame, std::size_t first,
                   std::span<const roi::PointXYZI> placed) override {
      for (KeyframeCase& c : *cases) {
        if (c.frame.start_time_ns != frame.start_time_ns) continue;
        if (c.points.size() < first + placed.size()) c.points.resize(first + placed.size());
        std::copy(placed.begin(), placed.end(), c.points.begin() + static_cast<std::ptrdiff_t>(first));
      }
    }
    void on_sweep(std::size_t, const pipeline::Sweep& sweep, double) override {
      for (std::size_t k = 0; k < cases->size(); ++k) {
        KeyframeCase& c = (*cases)[k];
        if (c.frame.start_time_ns != sweep.start_ns) continue;
        placed_ok[k] = sweep.filtered ? 1 : 0;
        status[k] = sweep.pose_status;
        c.s0_m = sweep.start_s_m;
      }
    }
  } collect;
  collect.cases = &cases;
  collect.placed_ok.assign(cases.size(), 0);
  collect.status.assign(cases.size(), pose::PoseStatus::kNoGnss);
  const daemon::DaemonConfig config = run.pipeline_config(RoiShape::kCircular, 25, mode);
  run_pipelines(run, std::span<const daemon::DaemonConfig>(&config, 1), collect, last_end);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    KeyframeCase& c = cases[k];
    if (collect.placed_ok[k] == 0 || c.points.size() != c.frame.points.size()) {
      throw std::runtime_error(run.dir().string() + ": keyframe '" + c.keyframe.name + "': no valid pose (" +
                               std::string(pose::to_string(collect.status[k])) + ")");
    }
    place_frame_truth(c.frame, run.truth(), run.robot_from_lidar(), c.truth);
    const pose::PoseQuery q = run.poses().pose_at(c.time_ns);
    if (!q.valid())
      throw std::runtime_error(run.dir().string() + ": keyframe '" + c.keyframe.name + "': no valid pose");
    c.robot_pose = q.global_from_robot;
  }
  return cases;
}

std::vector<KeyframeRow> run_keyframe_rows(const ScenarioRun& run, const std::vector<KeyframeCase>& cases,
                                           std::span<const RoiShape> shapes, std::span<const int> ratios_pct, int reps,
                                           PoseMode mode) {
  const sim::EvaluationSpec& e = run.scenario().evaluation;
  std::vector<daemon::DaemonConfig> configs;
  for (const RoiShape shape : shapes) {
    for (const int ratio : ratios_pct)
      configs.push_back(run.pipeline_config(shape, ratio, mode));
  }
  std::vector<KeyframeRow> rows;
  for (const RoiShape shape : shapes) {
    for (const KeyframeCase& c : cases) {
      for (const int ratio : ratios_pct)
        rows.push_back({c.keyframe.name, shape, ratio, {}, {}, {}, {}, {}});
    }
  }
  std::int64_t last_end = std::numeric_limits<std::int64_t>::min();
  for (const KeyframeCase& c : cases)
    last_end = std::max(last_end, c.frame.end_time_ns);
  // Row of configuration k (shape s, ratio r) and case c.
  const std::size_t n_ratios = ratios_pct.size();
  const auto row_of = [&](std::size_t k, std::size_t c) -> KeyframeRow& {
    return rows[((k / n_ratios) * cases.size() + c) * n_ratios + k % n_ratios];
  };
  struct Collect final : PipelineObserver {
    const std::vector<KeyframeCase>* cases;
    std::function<KeyframeRow&(std::size_t, std::size_t)> row;
    std::vector<std::size_t> samples;
    void on_sweep(std::size_t k, const pipeline::Sweep& sweep, double ms) override {
      for (std::size_t c = 0; c < cases->size(); ++c) {
        if ((*cases)[c].frame.start_time_ns != sweep.start_ns) continue;
        KeyframeRow& r = row(k, c);
        r.centres = sweep.centres;
        r.kept.assign(sweep.point_index.begin(), sweep.point_index.end());
        add_sample(r.time, samples[static_cast<std::size_t>(&r - &row(0, 0))], ms);
      }
    }
  } collect;
  collect.cases = &cases;
  collect.row = row_of;
  collect.samples.assign(rows.size(), 0);
  for (int rep = 0; rep < std::max(reps, 1); ++rep)
    run_pipelines(run, configs, collect, last_end);
  for (std::size_t k = 0; k < configs.size(); ++k) {
    for (std::size_t c = 0; c < cases.size(); ++c) {
      KeyframeRow& row = row_of(k, c);
      const KeyframeCase& kc = cases[c];
      if (row.centres.empty()) {
        throw std::runtime_error(run.dir().string() + ": keyframe '" + kc.keyframe.name +
                                 "': the pipeline gave no chain");
      }
      const bool circles = row.shape == RoiShape::kCircular;
      const double half_a = circles ? 0.0 : e.rect_height_m / 2.0;
      const TruthCorridor corridor(run.trajectory(), row.centres, half_a,
                                   circles ? e.circle_diameter_m : e.rect_width_m, !circles);
      row.truth.resize(kc.truth.size());
      for (std::size_t i = 0; i < kc.truth.size(); ++i) {
        row.truth[i] = corridor.contains(kc.truth[i].x, kc.truth[i].y) ? 1 : 0;
      }
      row.confusion = roi::confusion(row.kept, row.truth);
    }
  }
  return rows;
}

KeyframeRow run_keyframe_row(const ScenarioRun& run, const KeyframeCase& c, RoiShape shape, int ratio_pct, int reps,
                             PoseMode mode) {
  const std::vector<KeyframeCase> one{c};
  const std::array<RoiShape, 1> shapes{shape};
  const std::array<int, 1> ratios{ratio_pct};
  return std::move(run_keyframe_rows(run, one, shapes, ratios, reps, mode).front());
}

// ---- sequential ---------------------------------------------------------------------------

SequentialReport run_sequential(const ScenarioRun& run, PoseMode mode, int ratio_pct) {
  const std::array<daemon::DaemonConfig, 2> configs{run.pipeline_config(RoiShape::kCircular, ratio_pct, mode),
                                                    run.pipeline_config(RoiShape::kRectangular, ratio_pct, mode)};
  struct Collect final : PipelineObserver {
    SequentialReport report;
    std::map<std::uint64_t, FrameTiming> frames;   // complete sweeps with a valid pose, by index
    std::map<std::uint64_t, std::int64_t> starts;  // every complete sweep's start (the data cycle)
    std::size_t n_circ = 0, n_rect = 0;
    void on_sweep(std::size_t k, const pipeline::Sweep& sweep, double ms) override {
      if (sweep.partial) {
        if (k == 0) ++report.skipped_partial;
        return;
      }
      if (k == 0) starts[sweep.index] = sweep.start_ns;
      if (!sweep.filtered) {
        if (k == 0) ++report.skipped_no_pose;
        return;
      }
      FrameTiming& f = frames[sweep.index];
      f.frame_index = sweep.index;
      f.points = sweep.points_in;
      if (k == 0) {
        f.circular_ms = ms;
        add_sample(report.circular, n_circ, ms);
      } else {
        f.rectangular_ms = ms;
        add_sample(report.rectangular, n_rect, ms);
      }
    }
  } collect;
  run_pipelines(run, configs, collect);
  SequentialReport report = std::move(collect.report);
  // The cycle between consecutive complete sweeps, with or without a pose.
  std::size_t n_cycle = 0;
  std::map<std::uint64_t, double> cycle_ms;
  const std::int64_t first_start = collect.starts.empty() ? 0 : collect.starts.begin()->second;
  std::int64_t previous = 0;
  bool first = true;
  for (const auto& [index, start] : collect.starts) {
    const double ms = first ? 0.0 : static_cast<double>(start - previous) * 1e-6;
    if (!first) add_sample(report.cycle, n_cycle, ms);
    cycle_ms[index] = ms;
    first = false;
    previous = start;
  }
  double points_sum = 0.0;
  for (auto& [index, f] : collect.frames) {
    f.cycle_ms = cycle_ms[index];
    f.start_s = static_cast<double>(collect.starts[index] - first_start) * 1e-9;
    points_sum += static_cast<double>(f.points);
    report.per_frame.push_back(f);
  }
  report.frames = report.per_frame.size();
  report.avg_points = report.frames > 0 ? points_sum / static_cast<double>(report.frames) : 0.0;
  return report;
}

// ---- accumulated --------------------------------------------------------------------------

LinearFit fit_line(const std::vector<std::pair<double, double>>& samples) {
  LinearFit fit;
  const double n = static_cast<double>(samples.size());
  if (samples.size() < 2) return fit;
  double sx = 0, sy = 0;
  for (const auto& [x, y] : samples) {
    sx += x;
    sy += y;
  }
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (const auto& [x, y] : samples) {
    sxx += (x - mx) * (x - mx);
    sxy += (x - mx) * (y - my);
    syy += (y - my) * (y - my);
  }
  if (sxx <= 0.0) return fit;
  const double slope = sxy / sxx;
  fit.slope_ms_per_mpoint = slope * 1e6;
  fit.intercept_ms = my - slope * mx;
  fit.r2 = syy > 0.0 ? (sxy * sxy) / (sxx * syy) : 1.0;
  return fit;
}

AccumulatedReport run_accumulated(const ScenarioRun& run, PoseMode mode, int ratio_pct) {
  struct Accumulator {
    int frames_per_cloud;
    int frames = 0;
    std::vector<roi::PointXYZI> cloud;
    std::size_t clouds[2] = {0, 0};
    double points_sum = 0.0;
    TimingStats time[2];
  };
  struct Collect final : PipelineObserver {
    std::vector<Accumulator> acc;
    AccumulatedReport report;
    RoiChain* chain = nullptr;
    const ScenarioRun* run = nullptr;
    int ratio_pct = 25;
    std::vector<roi::PointXYZI> placed;  // the sweep in progress, in the global frame
    void on_placed(std::size_t, const vlp16::Frame& frame, std::size_t first,
                   std::span<const roi::PointXYZI> points) override {
      if (first == 0 || placed.size() > first) placed.clear();
      if (placed.size() < frame.points.size()) placed.reserve(frame.points.size());
      placed.insert(placed.end(), points.begin(), points.end());
    }
    void on_sweep(std::size_t, const pipeline::Sweep& sweep, double) override {
      const bool whole = !sweep.partial && sweep.filtered && placed.size() == sweep.points_in;
      if (!whole) {
        placed.clear();
        return;
      }
      const double look_ahead = run->scenario().evaluation.look_ahead_m;
      for (Accumulator& a : acc) {
        a.cloud.insert(a.cloud.end(), placed.begin(), placed.end());
        if (++a.frames < a.frames_per_cloud) continue;
        for (const RoiShape shape : {RoiShape::kCircular, RoiShape::kRectangular}) {
          const int k = shape == RoiShape::kCircular ? 0 : 1;
          const auto start = std::chrono::steady_clock::now();
          chain->run(run->trajectory(), sweep.start_s_m, look_ahead, shape, ratio_pct, a.cloud);
          const double ms = elapsed_ms(start);
          add_sample(a.time[k], a.clouds[k], ms);
          (k == 0 ? report.circular_samples : report.rectangular_samples)
              .emplace_back(static_cast<double>(a.cloud.size()), ms);
        }
        a.points_sum += static_cast<double>(a.cloud.size());
        a.cloud.clear();
        a.frames = 0;
      }
      placed.clear();
    }
  } collect;
  for (const int n : kAccumulations)
    collect.acc.push_back({n, 0, {}, {0, 0}, 0.0, {}});
  RoiChain chain(run.scenario().evaluation);
  collect.chain = &chain;
  collect.run = &run;
  collect.ratio_pct = ratio_pct;
  const daemon::DaemonConfig config = run.pipeline_config(RoiShape::kCircular, ratio_pct, mode);
  run_pipelines(run, std::span<const daemon::DaemonConfig>(&config, 1), collect);
  AccumulatedReport report = std::move(collect.report);
  for (const RoiShape shape : {RoiShape::kCircular, RoiShape::kRectangular}) {
    const int k = shape == RoiShape::kCircular ? 0 : 1;
    for (const Accumulator& a : collect.acc) {
      if (a.clouds[k] == 0) continue;
      report.rows.push_back(
          {shape, a.frames_per_cloud, a.clouds[k], a.points_sum / static_cast<double>(a.clouds[k]), a.time[k]});
    }
  }
  report.circular_fit = fit_line(report.circular_samples);
  report.rectangular_fit = fit_line(report.rectangular_samples);
  return report;
}

}  // namespace trajroi::eval
