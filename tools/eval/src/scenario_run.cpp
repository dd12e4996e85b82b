// A scenario run folder as the evaluations read it (ScenarioRun), the daemon's pipeline run
// over it (run_pipelines), the evaluation's ROI chains and the true placement of a frame.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "timing.hpp"
#include "trajroi/config/text_file.hpp"
#include "trajroi/eval/scenario_eval.hpp"
#include "trajroi/inputs/capture.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/transform.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::eval {
namespace fs = std::filesystem;

// ---- RoiChain -----------------------------------------------------------------------------

RoiChain::RoiChain(const sim::EvaluationSpec& spec)
    : spec_(spec),
      circles_(RoiShape::kCircular, roi::ChainSize{spec.circle_diameter_m / 2.0, 0.0, 0.0}),
      rects_(RoiShape::kRectangular, roi::ChainSize{0.0, spec.rect_height_m, spec.rect_width_m}) {}

void RoiChain::run(const roi::Trajectory& trajectory, double s0_m, double look_ahead_m, RoiShape shape, int ratio_pct,
                   std::span<const roi::PointXYZI> points) {
  const bool circular = shape == RoiShape::kCircular;
  roi::RoiChain& chain = circular ? circles_ : rects_;
  const double spacing =
      roi::spacing_from_ratio(ratio_pct / 100.0, circular ? spec_.circle_diameter_m : spec_.rect_height_m);
  chain.place(trajectory, s0_m, look_ahead_m, spacing,
              roi::ChainSize{spec_.circle_diameter_m / 2.0, spec_.rect_height_m, spec_.rect_width_m});
  (void)chain.filter(points, kept_);
  last_ = &chain;
}

// ---- ScenarioRun ---------------------------------------------------------------------------

ScenarioRun::ScenarioRun(const fs::path& dir) : dir_(dir) {
  sim::require_run_folder(dir);
  scenario_ = sim::load_scenario(dir / sim::kScenarioFile);
  trajectory_ = std::make_unique<roi::Trajectory>(roi::parse_trajectory_csv(
      config::read_text_file(dir / sim::kTrajectoryFile), (dir / sim::kTrajectoryFile).string()));
  robot_from_lidar_ = scenario_.robot.lidar.robot_from_sensor();
  // The daemon's configuration the simulator wrote for this run: sensors, delays, ranges.
  config_ = daemon::load_daemon_config(dir / sim::kDaemonConfigFile);

  // The pose over the whole run (for the keyframes' descriptions: the estimated robot pose at
  // the keyframe's time), from the recordings through the daemon's pose input, in the order
  // the daemon's merger gives them (an attitude is turned into the global frame at the latest
  // GNSS position).
  const std::size_t capacity = 1U << 20;
  poses_ = std::make_unique<pose::PoseBuffer>(config_.gate, config_.gnss_antenna_m, capacity);
  pose_input::PoseInput input(pose::GlobalFrame::local_cartesian(config_.origin), pipeline::pose_input_config(config_),
                              *poses_);
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

vlp16::StreamOptions ScenarioRun::stream_options() const {
  return pipeline::stream_options(config_);
}

daemon::DaemonConfig ScenarioRun::pipeline_config(RoiShape shape, int ratio_pct, daemon::PoseMode mode) const {
  daemon::DaemonConfig c = config_;
  const sim::EvaluationSpec& e = scenario_.evaluation;
  c.roi.shape = shape;
  c.roi.circle_diameter_m = e.circle_diameter_m;
  c.roi.rect_height_m = e.rect_height_m;
  c.roi.rect_width_m = e.rect_width_m;
  c.roi.spacing_ratio = ratio_pct / 100.0;
  c.roi.look_ahead_m = e.look_ahead_m;
  c.roi.look_ahead_per_mps_s = 0.0;
  c.roi.width_per_mps_s = 0.0;
  c.pose_mode = mode;
  c.buffers.max_points_per_sweep = 1U << 20;  // never truncate what is scored
  return c;
}

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
  vlp16::StreamDecoder decoder(pipeline::load_calibration(config_), stream_options());
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

// ---- the daemon's pipeline ------------------------------------------------------------------

void run_pipelines(const ScenarioRun& run, std::span<const daemon::DaemonConfig> configs, PipelineObserver& observer,
                   std::int64_t until_ns) {
  // Per configuration: its processor, and a sink that times the packets of each sweep.
  struct Lane final : pipeline::SweepSink {
    std::size_t index = 0;
    PipelineObserver* observer = nullptr;
    std::unique_ptr<pipeline::SweepProcessor> processor;
    double sweep_ms = 0.0;
    std::chrono::steady_clock::time_point packet_start;
    bool past_end = false;
    std::int64_t until_ns = 0;
    void on_sweep(pipeline::Sweep& sweep) override {
      sweep_ms += elapsed_ms(packet_start);
      observer->on_sweep(index, sweep, sweep_ms);
      sweep_ms = 0.0;
      packet_start = std::chrono::steady_clock::now();
      past_end = past_end || sweep.end_ns >= until_ns;
    }
    void on_placed(const vlp16::Frame& frame, std::size_t first, std::span<const roi::PointXYZI> placed) override {
      observer->on_placed(index, frame, first, placed);
    }
  };
  std::vector<Lane> lanes(configs.size());
  for (std::size_t k = 0; k < configs.size(); ++k) {
    lanes[k].index = k;
    lanes[k].observer = &observer;
    lanes[k].until_ns = until_ns;
    lanes[k].processor = std::make_unique<pipeline::SweepProcessor>(
        configs[k], std::make_unique<pipeline::ActiveTrajectory>(pipeline::ActiveTrajectory{run.trajectory(), 0}));
    lanes[k].processor->keep_point_indices();
  }
  inputs::RunMerger merger(run.dir());
  inputs::InputItem item;
  bool all_past = configs.empty();
  while (!all_past && merger.next(item)) {
    all_past = true;
    for (Lane& lane : lanes) {
      pipeline::SweepProcessor& p = *lane.processor;
      if (inputs::is_lidar(item.stream)) {
        lane.packet_start = std::chrono::steady_clock::now();
        p.process(item, lane);
        lane.sweep_ms += elapsed_ms(lane.packet_start);
        lane.packet_start = std::chrono::steady_clock::now();
      } else {
        p.process(item, lane);
      }
      all_past = all_past && lane.past_end;
    }
  }
  if (!all_past) {
    for (Lane& lane : lanes) {
      lane.packet_start = std::chrono::steady_clock::now();
      lane.processor->flush(lane);
    }
  }
}

// ---- placing frames -----------------------------------------------------------------------

void place_frame_truth(const vlp16::Frame& frame, const sim::TruthPoses& truth,
                       const Eigen::Isometry3d& robot_from_lidar, std::vector<roi::PointXYZd>& out) {
  out.clear();
  out.reserve(frame.points.size());
  for (const vlp16::Point& p : frame.points) {
    const sim::TruePose tp = truth.at(frame.start_time_ns + p.time_offset_ns);
    const Eigen::Isometry3d global_from_lidar = roi::pose_from_xy_yaw(tp.x_m, tp.y_m, tp.yaw_rad) * robot_from_lidar;
    const Eigen::Vector3d g = global_from_lidar * Eigen::Vector3d(static_cast<double>(p.x), static_cast<double>(p.y),
                                                                  static_cast<double>(p.z));
    out.push_back({g.x(), g.y(), g.z()});
  }
}

}  // namespace trajroi::eval
