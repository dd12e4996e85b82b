#include "trajroi/eval/scenario_eval.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/transform.hpp"
#include "trajroi/config/text_file.hpp"
#include "trajroi/inputs/capture.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::eval {
namespace fs = std::filesystem;
namespace {


template <typename Point>
void push_point(std::vector<Point>& out, const Eigen::Vector3d& p, float intensity) {
  if constexpr (std::is_same_v<Point, roi::PointXYZI>) {
    out.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), intensity});
  } else {
    out.push_back({p.x(), p.y(), p.z()});
  }
}

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

void add_sample(TimingStats& t, std::size_t& n, double ms) {
  if (n == 0) t = {ms, ms, 0.0};
  t.min_ms = std::min(t.min_ms, ms);
  t.max_ms = std::max(t.max_ms, ms);
  t.avg_ms += (ms - t.avg_ms) / static_cast<double>(++n);
}

}  // namespace

// ---- RoiChain -----------------------------------------------------------------------------

RoiChain::RoiChain(const sim::EvaluationSpec& spec)
    : spec_(spec), circles_(spec.circle_diameter_m / 2.0, {}), rects_(spec.rect_height_m, spec.rect_width_m, {}) {}

void RoiChain::run(const roi::Trajectory& trajectory, double s0_m, double look_ahead_m, RoiShape shape, int ratio_pct,
                   std::span<const roi::PointXYZI> points) {
  const bool circular = shape == RoiShape::kCircular;
  const double spacing = roi::spacing_from_ratio(ratio_pct / 100.0, circular ? spec_.circle_diameter_m : spec_.rect_height_m);
  roi::place_centres(trajectory, s0_m, look_ahead_m, spacing, centres_);
  if (circular) {
    circles_.assign(centres_);
    circle_grid_.build(circles_);
    circle_grid_.filter(points, kept_);
  } else {
    rects_.assign(centres_);
    rect_grid_.build(rects_);
    rect_grid_.filter(points, kept_);
  }
}

// ---- ScenarioRun ---------------------------------------------------------------------------

ScenarioRun::ScenarioRun(const fs::path& dir) : dir_(dir) {
  sim::require_run_folder(dir);
  scenario_ = sim::load_scenario(dir / sim::kScenarioFile);
  trajectory_ = std::make_unique<roi::Trajectory>(
      roi::parse_trajectory_csv(config::read_text_file(dir / sim::kTrajectoryFile), (dir / sim::kTrajectoryFile).string()));
  robot_from_lidar_ = scenario_.robot.lidar.robot_from_sensor();

  // The pose, from the recorded streams through the drivers and the pose library. The gate
  // is the daemon's default; the buffer holds the whole run (an offline evaluation).
  pose::PoseGate gate;
  const std::size_t capacity = 1U << 20;
  poses_ = std::make_unique<pose::PoseBuffer>(gate, scenario_.robot.gnss_antenna_m, capacity);
  pose_input::PoseInputConfig config;
  config.imu.magnetic_declination_deg = scenario_.imu.magnetic_declination_deg;
  config.gnss_delay_ns = std::llround(sim::gnss_delay_s(scenario_.gnss) * 1e9);
  config.imu_delay_ns = std::llround(sim::imu_delay_s(scenario_.imu) * 1e9);
  pose_input::PoseInput input(pose::GlobalFrame::local_cartesian(scenario_.origin), config, *poses_);
  // The two recordings in receive-time order (the daemon's merger), as a live daemon gets
  // them (an attitude is turned into the global frame at the latest GNSS position).
  inputs::RunMerger merger(dir, inputs::RunStreams{false, true, true});
  inputs::InputItem item;
  while (merger.next(item)) {
    if (item.stream == inputs::Stream::kGnss) {
      input.gnss_bytes(item.bytes, item.receive_ns);
    } else {
      input.imu_bytes(item.bytes, item.receive_ns);
    }
  }
  pose_counters_ = input.counters();
  truth_ = std::make_unique<sim::TruthPoses>(dir / sim::kTruthPosesFile);
  labels_ = sim::read_truth_labels(dir / sim::kTruthLabelsFile);
}

ScenarioRun::~ScenarioRun() = default;

vlp16::StreamCounters ScenarioRun::for_each_frame(const FrameCallback& on_frame) const {
  struct Sink final : vlp16::FrameSink {
    const FrameCallback* callback;
    std::uint64_t next_point = 0;
    double decode_ms = 0.0;
    void on_frame(const vlp16::Frame& frame) override {
      (*callback)(frame, next_point, decode_ms);
      next_point += frame.points.size();
      decode_ms = 0.0;
    }
  } sink;
  sink.callback = &on_frame;
  vlp16::StreamDecoder decoder(vlp16::Calibration::vlp16_default(), {});
  vlp16::PcapSource source(dir_ / sim::kLidarFile);
  inputs::CaptureDecoder capture(source, decoder);
  for (;;) {
    const auto start = std::chrono::steady_clock::now();
    const auto next = capture.step(sink);
    if (next == vlp16::PacketSource::Next::kEnd) break;
    if (next != vlp16::PacketSource::Next::kDatagram) {
      throw std::runtime_error((dir_ / sim::kLidarFile).string() + ": " + source.error());
    }
    sink.decode_ms += elapsed_ms(start);
  }
  return decoder.counters();
}

// ---- placing frames -----------------------------------------------------------------------

bool place_frame(const vlp16::Frame& frame, const pose::PoseBuffer& poses, const Eigen::Isometry3d& robot_from_lidar,
                 PoseMode mode, std::vector<roi::PointXYZI>& out, pose::PoseStatus& status) {
  out.clear();
  out.reserve(frame.points.size());
  // Per frame: one query at the frame's middle, a period longer than any frame.
  const bool per_frame = mode == PoseMode::kPerFrame;
  pose::FiringPoses firing(poses, robot_from_lidar,
                           per_frame ? std::numeric_limits<std::int64_t>::max() : vlp16::kFiringCycle_ns);
  const Eigen::Isometry3d* global_from_lidar = nullptr;
  if (per_frame) {
    global_from_lidar = firing.at(frame.start_time_ns + (frame.end_time_ns - frame.start_time_ns) / 2, status);
    if (global_from_lidar == nullptr) return false;
  }
  for (const vlp16::Point& p : frame.points) {
    if (!per_frame) {
      global_from_lidar = firing.at(frame.start_time_ns + p.time_offset_ns, status);
      if (global_from_lidar == nullptr) return false;
    }
    push_point(out, *global_from_lidar * Eigen::Vector3d(p.x, p.y, p.z), static_cast<float>(p.intensity));
  }
  status = pose::PoseStatus::kValid;
  return true;
}

void place_frame_truth(const vlp16::Frame& frame, const sim::TruthPoses& truth,
                       const Eigen::Isometry3d& robot_from_lidar, std::vector<roi::PointXYZd>& out) {
  out.clear();
  out.reserve(frame.points.size());
  for (const vlp16::Point& p : frame.points) {
    const sim::TruePose tp = truth.at(frame.start_time_ns + p.time_offset_ns);
    const Eigen::Isometry3d global_from_lidar = roi::pose_from_xy_yaw(tp.x_m, tp.y_m, tp.yaw_rad) * robot_from_lidar;
    push_point(out, global_from_lidar * Eigen::Vector3d(p.x, p.y, p.z), 0.0f);
  }
}

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
  std::vector<bool> found(cases.size(), false);
  run.for_each_frame([&](const vlp16::Frame& frame, std::uint64_t, double) {
    if (frame.partial) return;
    for (std::size_t k = 0; k < cases.size(); ++k) {
      if (!found[k] && frame.start_time_ns <= cases[k].time_ns && cases[k].time_ns < frame.end_time_ns) {
        cases[k].frame = frame;
        cases[k].frame_index = frame.index;
        found[k] = true;
      }
    }
  });
  for (std::size_t k = 0; k < cases.size(); ++k) {
    KeyframeCase& c = cases[k];
    if (!found[k]) throw std::runtime_error(run.dir().string() + ": no complete frame at keyframe '" + c.keyframe.name + "'");
    pose::PoseStatus status{};
    if (!place_frame(c.frame, run.poses(), run.robot_from_lidar(), mode, c.points, status)) {
      throw std::runtime_error(run.dir().string() + ": keyframe '" + c.keyframe.name + "': no valid pose (" +
                               std::string(pose::to_string(status)) + ")");
    }
    place_frame_truth(c.frame, run.truth(), run.robot_from_lidar(), c.truth);
    const pose::PoseQuery q = run.poses().pose_at(c.time_ns);
    if (!q.valid()) throw std::runtime_error(run.dir().string() + ": keyframe '" + c.keyframe.name + "': no valid pose");
    c.robot_pose = q.global_from_robot;
    c.s0_m = run.trajectory().project(q.global_from_robot.translation().head<2>()).s_m;
  }
  return cases;
}

KeyframeRow run_keyframe_row(const ScenarioRun& run, const KeyframeCase& c, RoiShape shape, int ratio_pct, int reps,
                             PoseMode mode) {
  const sim::EvaluationSpec& e = run.scenario().evaluation;
  KeyframeRow row{c.keyframe.name, shape, ratio_pct, {}, {}, {}, {}, {}};
  RoiChain chain(e);
  std::vector<roi::PointXYZI> placed;
  pose::PoseStatus status{};
  row.time = time_repeated(reps, [&] {
    (void)place_frame(c.frame, run.poses(), run.robot_from_lidar(), mode, placed, status);
    chain.run(run.trajectory(), c.s0_m, e.look_ahead_m, shape, ratio_pct, placed);
  });
  row.centres = chain.centres();
  row.kept = chain.kept();
  const bool circles = shape == RoiShape::kCircular;
  const double half_a = circles ? 0.0 : e.rect_height_m / 2.0;
  const TruthCorridor corridor(run.trajectory(), row.centres, half_a, circles ? e.circle_diameter_m : e.rect_width_m,
                               !circles);
  row.truth.resize(c.truth.size());
  for (std::size_t i = 0; i < c.truth.size(); ++i) row.truth[i] = corridor.contains(c.truth[i].x, c.truth[i].y) ? 1 : 0;
  row.confusion = roi::confusion(row.kept, row.truth);
  return row;
}

// ---- sequential ---------------------------------------------------------------------------

SequentialReport run_sequential(const ScenarioRun& run, PoseMode mode, int ratio_pct) {
  SequentialReport report;
  RoiChain chain(run.scenario().evaluation);
  const double look_ahead = run.scenario().evaluation.look_ahead_m;
  std::vector<roi::PointXYZI> placed;
  std::size_t n_cycle = 0, n_circ = 0, n_rect = 0;
  std::int64_t previous_start = 0, first_start = 0;
  bool have_previous = false;
  double s_hint = 0.0;
  double points_sum = 0.0;
  run.for_each_frame([&](const vlp16::Frame& frame, std::uint64_t, double decode_ms) {
    if (frame.partial) {
      ++report.skipped_partial;
      return;
    }
    FrameTiming ft{frame.index, 0.0, 0.0, frame.points.size(), 0.0, 0.0};
    if (have_previous) {
      ft.cycle_ms = static_cast<double>(frame.start_time_ns - previous_start) * 1e-6;
      add_sample(report.cycle, n_cycle, ft.cycle_ms);
    } else {
      first_start = frame.start_time_ns;
    }
    have_previous = true;
    previous_start = frame.start_time_ns;
    ft.start_s = static_cast<double>(frame.start_time_ns - first_start) * 1e-9;

    // Each shape is timed as the whole pipeline, so the frame is placed once per shape.
    for (const RoiShape shape : {RoiShape::kCircular, RoiShape::kRectangular}) {
      const auto start = std::chrono::steady_clock::now();
      pose::PoseStatus status{};
      if (!place_frame(frame, run.poses(), run.robot_from_lidar(), mode, placed, status)) {
        if (shape == RoiShape::kCircular) ++report.skipped_no_pose;
        return;
      }
      const pose::PoseQuery q = run.poses().pose_at(frame.end_time_ns);
      if (!q.valid()) return;
      const double s0 = run.trajectory().project(q.global_from_robot.translation().head<2>(), s_hint, 50.0).s_m;
      chain.run(run.trajectory(), s0, look_ahead, shape, ratio_pct, placed);
      const double ms = decode_ms + elapsed_ms(start);
      if (shape == RoiShape::kCircular) {
        ft.circular_ms = ms;
        add_sample(report.circular, n_circ, ms);
      } else {
        s_hint = s0;
        ft.rectangular_ms = ms;
        add_sample(report.rectangular, n_rect, ms);
      }
    }
    points_sum += static_cast<double>(frame.points.size());
    ++report.frames;
    report.per_frame.push_back(ft);
  });
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
  std::vector<Accumulator> acc;
  for (const int n : kAccumulations) acc.push_back({n, 0, {}, {0, 0}, 0.0, {}});
  AccumulatedReport report;
  RoiChain chain(run.scenario().evaluation);
  const double look_ahead = run.scenario().evaluation.look_ahead_m;
  std::vector<roi::PointXYZI> placed;
  double s_hint = 0.0;
  run.for_each_frame([&](const vlp16::Frame& frame, std::uint64_t, double) {
    if (frame.partial) return;
    pose::PoseStatus status{};
    if (!place_frame(frame, run.poses(), run.robot_from_lidar(), mode, placed, status)) return;
    const pose::PoseQuery q = run.poses().pose_at(frame.end_time_ns);
    if (!q.valid()) return;
    const double s0 = run.trajectory().project(q.global_from_robot.translation().head<2>(), s_hint, 50.0).s_m;
    s_hint = s0;
    for (Accumulator& a : acc) {
      a.cloud.insert(a.cloud.end(), placed.begin(), placed.end());
      if (++a.frames < a.frames_per_cloud) continue;
      for (const RoiShape shape : {RoiShape::kCircular, RoiShape::kRectangular}) {
        const int k = shape == RoiShape::kCircular ? 0 : 1;
        const auto start = std::chrono::steady_clock::now();
        chain.run(run.trajectory(), s0, look_ahead, shape, ratio_pct, a.cloud);
        const double ms = elapsed_ms(start);
        add_sample(a.time[k], a.clouds[k], ms);
        (k == 0 ? report.circular_samples : report.rectangular_samples)
            .emplace_back(static_cast<double>(a.cloud.size()), ms);
      }
      a.points_sum += static_cast<double>(a.cloud.size());
      a.cloud.clear();
      a.frames = 0;
    }
  });
  for (const RoiShape shape : {RoiShape::kCircular, RoiShape::kRectangular}) {
    const int k = shape == RoiShape::kCircular ? 0 : 1;
    for (const Accumulator& a : acc) {
      if (a.clouds[k] == 0) continue;
      report.rows.push_back({shape, a.frames_per_cloud, a.clouds[k], a.points_sum / static_cast<double>(a.clouds[k]),
                             a.time[k]});
    }
  }
  report.circular_fit = fit_line(report.circular_samples);
  report.rectangular_fit = fit_line(report.rectangular_samples);
  return report;
}

}  // namespace trajroi::eval
