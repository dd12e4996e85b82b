#pragma once

// The paper's evaluations on a simulated run (Tables 9, 11, 18, 19 and 20), through the
// daemon's own per-sweep pipeline: the run's recordings merged as trajroid merges them and fed
// to pipeline::SweepProcessor (decode, pose per firing or per sweep, transform, ROI chain placed
// at the sweep's start from the robot's projection, exact filter), configured from the run's
// trajroid.yaml with the scenario's evaluation sizes. The simulator's truth (the true pose at
// every firing) says where each measured point really is, so pose errors show in the figures.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "trajroi/daemon/config.hpp"
#include "trajroi/eval/artificial.hpp"
#include "trajroi/eval/timing.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/pose/pose_buffer.hpp"
#include "trajroi/pose_input/pose_input.hpp"
#include "trajroi/roi/centres.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/metrics.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/roi_chain.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/trajectory.hpp"
#include "trajroi/sim/run_folder.hpp"
#include "trajroi/sim/scenario.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::eval {

// A run folder opened for evaluation. Throws std::runtime_error (or config::ConfigError for
// its scenario.yaml) naming what is wrong when `dir` is not a complete run.
class ScenarioRun {
 public:
  explicit ScenarioRun(const std::filesystem::path& dir);
  ~ScenarioRun();

  [[nodiscard]] const std::filesystem::path& dir() const noexcept { return dir_; }
  [[nodiscard]] const sim::Scenario& scenario() const noexcept { return scenario_; }
  [[nodiscard]] const roi::Trajectory& trajectory() const noexcept { return *trajectory_; }
  [[nodiscard]] const pose::PoseBuffer& poses() const noexcept { return *poses_; }
  [[nodiscard]] const pose_input::PoseInputCounters& pose_counters() const noexcept { return pose_counters_; }
  [[nodiscard]] const sim::TruthPoses& truth() const noexcept { return *truth_; }
  [[nodiscard]] const std::vector<std::uint8_t>& labels() const noexcept { return labels_; }
  [[nodiscard]] const Eigen::Isometry3d& robot_from_lidar() const noexcept { return robot_from_lidar_; }
  // The decoder's options, as the daemon's configuration for this run sets them.
  // What the daemon decodes this run with: the configured calibration and options.
  [[nodiscard]] vlp16::Calibration calibration() const { return pipeline::load_calibration(config_); }
  [[nodiscard]] vlp16::StreamOptions stream_options() const;
  // The daemon's configuration for this run (its trajroid.yaml), with the evaluation's ROI:
  // `shape` at `ratio_pct` % of its size along the trajectory, the scenario's look-ahead, and
  // `mode`.
  [[nodiscard]] daemon::DaemonConfig pipeline_config(RoiShape shape, int ratio_pct, daemon::PoseMode mode) const;

  // Decodes lidar.pcap and calls on_frame(frame, index of its first point in the whole run,
  // wall time spent decoding the packets since the previous frame in ms) for every frame,
  // partial ones included, in order. Returns the decoder's counters.
  using FrameCallback = std::function<void(const vlp16::Frame&, std::uint64_t first_point, double decode_ms)>;
  vlp16::StreamCounters for_each_frame(const FrameCallback& on_frame) const;

 private:
  std::filesystem::path dir_;
  sim::Scenario scenario_;
  std::unique_ptr<roi::Trajectory> trajectory_;
  std::unique_ptr<pose::PoseBuffer> poses_;
  pose_input::PoseInputCounters pose_counters_;
  std::unique_ptr<sim::TruthPoses> truth_;
  std::vector<std::uint8_t> labels_;
  Eigen::Isometry3d robot_from_lidar_ = Eigen::Isometry3d::Identity();
  daemon::DaemonConfig config_;
};

// How a sweep's points get their pose: one per firing sequence (55.3 µs, motion-compensated)
// or one for the whole sweep, at its start (the paper's way): the daemon's pose.mode.
using daemon::PoseMode;

// What one pass of the daemon's pipeline over the run reports.
class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  // Each sweep of configuration `config`, with the time the processor spent on its packets
  // (decode, pose, transform, ROI), in ms.
  virtual void on_sweep(std::size_t config, const pipeline::Sweep& sweep, double processing_ms) = 0;
  // Each run of points placed in the global frame (while the sweep's pose is valid).
  virtual void on_placed(std::size_t /*config*/, const vlp16::Frame& /*frame*/, std::size_t /*first*/,
                         std::span<const roi::PointXYZI> /*placed*/) {}
};

// One pass over the run's recordings (merged by receive time, as trajroid's replay) through one
// pipeline::SweepProcessor per configuration, sweeps carrying their point indices. Stops after
// the sweep that ends at or after `until_ns`.
void run_pipelines(const ScenarioRun& run, std::span<const daemon::DaemonConfig> configs, PipelineObserver& observer,
                   std::int64_t until_ns = std::numeric_limits<std::int64_t>::max());

// Where the frame's measured points really are: each placed with the true pose at its time.
void place_frame_truth(const vlp16::Frame& frame, const sim::TruthPoses& truth,
                       const Eigen::Isometry3d& robot_from_lidar, std::vector<roi::PointXYZd>& out);

// The evaluation's chains filtering one cloud: roi::RoiChain (the daemon's own) for each shape
// at the scenario's evaluation sizes, the spacing a ratio of the shape's size along the
// trajectory. Storage is reused from call to call.
class RoiChain {
 public:
  explicit RoiChain(const sim::EvaluationSpec& spec);
  void run(const roi::Trajectory& trajectory, double s0_m, double look_ahead_m, RoiShape shape, int ratio_pct,
           std::span<const roi::PointXYZI> points);
  [[nodiscard]] const std::vector<roi::Centre>& centres() const noexcept { return last_->centres(); }
  [[nodiscard]] const roi::IndexVector& kept() const noexcept { return kept_; }

 private:
  sim::EvaluationSpec spec_;
  roi::RoiChain circles_;
  roi::RoiChain rects_;
  const roi::RoiChain* last_ = &circles_;
  roi::IndexVector kept_;
};

// The ground truth a chain is scored against (the paper's matching of the chain's ends).
// Ground truth for one chain: within width/2 of the trajectory between arc lengths s0 and
// s1 (round ends); with square ends also in front of the first ROI's back edge and behind the
// last ROI's front edge — the planes through c_first − a/2·u_first and c_last + a/2·u_last.
class TruthCorridor {
 public:
  TruthCorridor(const roi::Trajectory& t, std::span<const roi::Centre> centres, double half_along_m, double width_m,
                bool square_ends)
      : set_(t, centres.front().s_m - half_along_m, centres.back().s_m + half_along_m, width_m), square_(square_ends) {
    const roi::Centre& first = centres.front();
    const roi::Centre& last = centres.back();
    start_dir_ = {std::cos(first.theta_rad), std::sin(first.theta_rad)};
    end_dir_ = {std::cos(last.theta_rad), std::sin(last.theta_rad)};
    start_ = first.position - half_along_m * start_dir_;
    end_ = last.position + half_along_m * end_dir_;
  }
  [[nodiscard]] bool contains(double x, double y) const noexcept {
    if (square_) {
      const Eigen::Vector2d p(x, y);
      if ((p - start_).dot(start_dir_) < 0.0 || (p - end_).dot(end_dir_) > 0.0) return false;
    }
    for (std::size_t j = 0; j < set_.size(); ++j) {
      if (set_.contains(j, x, y)) return true;
    }
    return false;
  }

 private:
  roi::CorridorRoiSet set_;
  bool square_;
  Eigen::Vector2d start_, end_, start_dir_, end_dir_;
};

// ---- Tables 9 and 11: keyframes --------------------------------------------------------------

struct KeyframeCase {
  sim::Keyframe keyframe;
  std::int64_t time_ns = 0;  // when the true robot is nearest the keyframe pose
  std::uint64_t frame_index = 0;
  std::vector<roi::PointXYZI> points;                            // global frame, placed by the daemon's pipeline
  std::vector<roi::PointXYZd> truth;                             // global frame, true pose
  Eigen::Isometry3d robot_pose = Eigen::Isometry3d::Identity();  // estimated, at time_ns
  double s0_m = 0.0;   // the robot's projection on the trajectory at the sweep's start
  vlp16::Frame frame;  // as decoded (sensor frame)
};

// Finds each keyframe's frame and prepares it: its points placed by the daemon's pipeline, the
// robot's projection where the daemon placed the chain. Throws std::runtime_error when a
// keyframe is not near the run's path or its pose is not valid.
[[nodiscard]] std::vector<KeyframeCase> keyframe_cases(const ScenarioRun& run, PoseMode mode);

struct KeyframeRow {
  std::string keyframe;
  RoiShape shape;
  int ratio_pct;
  std::vector<roi::Centre> centres;
  roi::Confusion confusion;
  TimingStats time;
  roi::IndexVector kept;
  std::vector<std::uint8_t> truth;  // per point: in the ground-truth corridor matched to this chain
};

// The rows of every case × shape × ratio (in that nesting: row (s, c, r) is at
// (s · cases + c) · ratios + r): the daemon's pipeline with that shape and spacing ratio,
// kept points and chain of the keyframe's sweep; ground truth: the corridor of the ROI's width
// from the chain's first to its last centre, with round ends (circles) or extended by a/2 with
// square ends (rectangles), so only the middle of the chains is compared (the paper's matching
// of the ends). Time: the processor's time on the sweep's packets (decode, pose, transform,
// chain, grid and filter) over `reps` passes of the run.
[[nodiscard]] std::vector<KeyframeRow> run_keyframe_rows(const ScenarioRun& run, const std::vector<KeyframeCase>& cases,
                                                         std::span<const RoiShape> shapes,
                                                         std::span<const int> ratios_pct, int reps, PoseMode mode);
// One row (one pass per repetition).
[[nodiscard]] KeyframeRow run_keyframe_row(const ScenarioRun& run, const KeyframeCase& c, RoiShape shape, int ratio_pct,
                                           int reps, PoseMode mode);

// ---- Table 18: sequential frames ------------------------------------------------------------

struct FrameTiming {
  std::uint64_t frame_index;
  double start_s;   // after the first frame
  double cycle_ms;  // since the previous frame's start (0 for the first)
  std::size_t points;
  double circular_ms;
  double rectangular_ms;
};

struct SequentialReport {
  std::size_t frames = 0;  // complete frames with a valid pose
  std::size_t skipped_no_pose = 0;
  std::size_t skipped_partial = 0;
  double avg_points = 0.0;
  TimingStats cycle, circular, rectangular;
  std::vector<FrameTiming> per_frame;
};

// Every complete sweep through the daemon's pipeline (both shapes, 25 %): the processor's time
// on its packets (decode included).
[[nodiscard]] SequentialReport run_sequential(const ScenarioRun& run, PoseMode mode, int ratio_pct = 25);

// ---- Table 19: accumulated frames -----------------------------------------------------------

inline constexpr std::array<int, 7> kAccumulations{1, 5, 10, 25, 50, 75, 100};

struct AccumulatedRow {
  RoiShape shape;
  int frames_per_cloud;
  std::size_t clouds;
  double avg_points;
  TimingStats time;
};

struct LinearFit {
  double slope_ms_per_mpoint = 0.0;
  double intercept_ms = 0.0;
  double r2 = 0.0;
};

struct AccumulatedReport {
  std::vector<AccumulatedRow> rows;
  LinearFit circular_fit, rectangular_fit;
  // Every cloud's (points, ms), for the plot.
  std::vector<std::pair<double, double>> circular_samples, rectangular_samples;
};

// Consecutive complete sweeps placed in the global frame by the daemon's pipeline and joined N
// at a time; each cloud filtered once per shape (centres from the daemon's projection at its
// last sweep's start; time: centres, ROI set, grid and filter) at 25 %.
[[nodiscard]] AccumulatedReport run_accumulated(const ScenarioRun& run, PoseMode mode, int ratio_pct = 25);

[[nodiscard]] LinearFit fit_line(const std::vector<std::pair<double, double>>& samples_points_ms);

}  // namespace trajroi::eval
