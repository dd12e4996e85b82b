#pragma once

// The per-sweep pipeline, without a thread: input items in (LiDAR datagrams, GNSS and IMU
// bytes, localization messages, each with its host receive time), filtered sweeps out. Pure
// and deterministic: the same items in the same order give the same sweeps, which is what
// makes a replay exact. The daemon's processing thread, the evaluations, and the tests all run
// it through its one entry, process().
//
// Per packet, as it arrives: decode (vlp16::StreamDecoder) → the sensor's pose at each
// firing's time (pose::FiringPoses, or one pose for the sweep) → placement in the global frame
// (roi::transform_records) → ROI membership (roi::RoiChain, exact) → append the kept points to
// the sweep. At a sweep's first packet the ROI chain is placed: centres every d from the
// robot's projection on the active trajectory over the look-ahead (growing with speed when
// configured); a new trajectory offered in between is swapped in there, never inside a sweep.
// At the sweep's end the sweep goes to the SweepSink.
//
// No allocation once warm: every buffer is sized at construction (points per sweep up to
// buffers.max_points_per_sweep; more are counted as truncated) and reused.
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "trajroi/daemon/config.hpp"
#include "trajroi/inputs/input_source.hpp"
#include "trajroi/pipeline/sweep.hpp"
#include "trajroi/pipeline/sweep_merger.hpp"
#include "trajroi/pose/pose_buffer.hpp"
#include "trajroi/pose_input/pose_input.hpp"
#include "trajroi/roi/roi_chain.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::pipeline {

using daemon::DaemonConfig;
using daemon::PoseMode;
using daemon::PoseSource;

struct ProcessorCounters {
  std::uint64_t sweeps = 0;
  std::uint64_t sweeps_filtered = 0;
  std::uint64_t sweeps_without_pose = 0;
  std::uint64_t points_in = 0;
  std::uint64_t points_kept = 0;
  std::uint64_t points_truncated = 0;
  std::uint64_t trajectory_swaps = 0;
  std::uint64_t projection_reacquired = 0;    // the robot far from where progress along the trajectory put it
  std::uint64_t pose_messages_malformed = 0;  // pose_input_t that did not decode, or unknown clock / frame
  std::uint64_t lidar_unknown_sender = 0;     // several LiDARs: a datagram from no configured sensor's address
};

// The configured calibration (lidar.calibration; the manual's values when none) and decoding
// options (ranges, the sweep's cut azimuth): what the processor decodes with. Throws
// config::ConfigError for a calibration file that cannot be read or parsed.
// `key`: how its errors name the LiDAR's keys (DaemonConfig::lidar_key).
[[nodiscard]] vlp16::Calibration load_calibration(const DaemonConfig::Lidar& lidar, const std::string& key = "lidar");
[[nodiscard]] vlp16::StreamOptions stream_options(const DaemonConfig::Lidar& lidar);
[[nodiscard]] inline vlp16::Calibration load_calibration(const DaemonConfig& config) {
  return load_calibration(config.lidar);
}
[[nodiscard]] inline vlp16::StreamOptions stream_options(const DaemonConfig& config) {
  return stream_options(config.lidar);
}

// The decoded points a sweep holds for outputs.raw_points: buffers.max_points_per_sweep /
// outputs.raw_points_decimation (0 when off); more are left out.
[[nodiscard]] std::size_t raw_points_capacity(const DaemonConfig& config) noexcept;
// The kept points a sweep handed on holds at most: buffers.max_points_per_sweep, for each
// LiDAR when several are merged.
[[nodiscard]] inline std::size_t sweep_points_capacity(const DaemonConfig& config) noexcept {
  return config.buffers.max_points_per_sweep * (config.lidar_merge.per_sensor ? 1 : config.lidars.size());
}

// How the configuration sets up the pose input (IMU mounting and declination, the delays).
[[nodiscard]] pose_input::PoseInputConfig pose_input_config(const DaemonConfig& config);

class SweepProcessor {
 public:
  SweepProcessor(const DaemonConfig& config, std::unique_ptr<ActiveTrajectory> trajectory);
  ~SweepProcessor();

  // Times the ROI filter's scans for the configured shape on its start-up grid and makes
  // the fastest on this machine the one used (roi::RoiChain::calibrate); at start, before
  // the first sweep.
  roi::ScanCalibration calibrate_scan() const { return lanes_[0]->chain.calibrate(); }
  // Makes the sweep it fills resident (Sweep::make_resident); at start, before the first
  // datagram.
  void make_resident();

  // The one entry: an input item of any stream, in the inputs' global order. LiDAR data
  // packets are decoded and their points placed and filtered, sweeps going to `sink` as they
  // end; position packets give the sensor's clock; GNSS and IMU bytes and localization messages
  // (pose.source lcm: 8 bytes of CLOCK_REALTIME − CLOCK_MONOTONIC at receipt, little-endian,
  // then the pose_input_t; one that does not decode is counted) feed the pose. `decoded`: a data
  // packet's points decoded ahead by lidar_stream().decoder_for() on another thread, or null.
  void process(const inputs::InputItem& item, SweepSink& sink, const vlp16::DecodedPacket* decoded = nullptr);
  // The packet decoder the stream decodes with: const and stateless, for another thread to
  // decode packets ahead.
  [[nodiscard]] const vlp16::PacketDecoder& packet_decoder() const noexcept { return lanes_[0]->decoder.decoder(); }
  [[nodiscard]] const vlp16::StreamDecoder& lidar_stream(std::size_t lane = 0) const noexcept {
    return lanes_[lane]->decoder;
  }
  // Several LiDARs (lidars:): one lane each, in the configuration's order. The lane a LiDAR
  // datagram is for, by its destination port and sender (-1: no configured sensor's). Const:
  // the input threads route with it to decode ahead.
  [[nodiscard]] std::size_t lane_count() const noexcept { return lanes_.size(); }
  [[nodiscard]] int lane_for(const inputs::InputItem& item) const noexcept;
  // The merge of several LiDARs' sweeps (null with one LiDAR).
  [[nodiscard]] const SweepMerger* merger() const noexcept { return merger_.get(); }
  // The input time of the newest item processed.
  [[nodiscard]] std::int64_t input_time_ns() const noexcept { return now_ns_; }
  // Steady-clock time the next datagram entered the daemon: a sweep keeps that of the last
  // datagram that gave it points (for the latency figures; no effect on the output).
  void set_input_arrival(std::int64_t steady_ns) noexcept { arrival_ns_ = steady_ns; }
  // Live: the host's CLOCK_REALTIME − CLOCK_MONOTONIC now (refreshed each second), for the
  // sweeps' UTC and the host clock's offset from GNSS time. Unset in a replay.
  void set_host_utc_offset(std::optional<std::int64_t> offset_ns) noexcept { host_utc_offset_ns_ = offset_ns; }
  // Host UTC − GNSS UTC at the newest GNSS epoch with a valid time, s (NaN: not both known).
  [[nodiscard]] double host_minus_gnss_utc_s() const noexcept;
  // NAV-PVT's time accuracy (tAcc) of that UTC, s (NaN: none).
  [[nodiscard]] double gnss_time_accuracy_s() const noexcept;
  // Host UTC − a LiDAR's PPS-locked UTC at the newest sweep it stamped (NaN: none, or not locked).
  [[nodiscard]] double host_minus_lidar_utc_s(std::size_t lane = 0) const noexcept {
    return lanes_[lane]->host_minus_lidar_utc_s;
  }
  // Ends the stream: the sweep in progress goes out (partial).
  void flush(SweepSink& sink);
  // Sweeps carry point_index from now on (the evaluations; the daemon does not need it).
  void keep_point_indices();

  // A new trajectory, taking effect at the next sweep's start. One offered before the
  // previous one took effect replaces it (that one is handed back by take_retired()).
  void offer_trajectory(std::unique_ptr<ActiveTrajectory> trajectory);
  // A trajectory no longer used, for the caller to free outside the real-time path.
  [[nodiscard]] std::unique_ptr<ActiveTrajectory> take_retired() noexcept;
  [[nodiscard]] std::int32_t active_trajectory_id() const noexcept { return active_->id; }
  // The trajectory filtered with now (not while another thread runs process()).
  [[nodiscard]] const ActiveTrajectory& active_trajectory() const noexcept { return *active_; }

  [[nodiscard]] const ProcessorCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const vlp16::StreamCounters& lidar_counters(std::size_t lane = 0) const noexcept {
    return lanes_[lane]->decoder.counters();
  }
  [[nodiscard]] const std::optional<vlp16::PositionPacket>& lidar_position(std::size_t lane = 0) const noexcept {
    return lanes_[lane]->decoder.last_position();
  }
  [[nodiscard]] const pose_input::PoseInput& pose_input() const noexcept { return pose_input_; }
  [[nodiscard]] const pose::PoseBuffer& poses() const noexcept { return poses_; }
  // The robot's distance to the active trajectory at the last sweep with a pose (NaN before).
  [[nodiscard]] double trajectory_distance_m() const noexcept { return trajectory_distance_m_; }
  // Why the last packet rejected for its model was ("product id 0x28 (VLP-32C) is not
  // supported"), empty if none was.
  [[nodiscard]] const std::string& lidar_model_reason(std::size_t lane = 0) const noexcept {
    return lanes_[lane]->decoder.model_check().reason();
  }
  // The sweep being built (its pose status tells why a sweep is withheld).
  [[nodiscard]] const Sweep& current(std::size_t lane = 0) const noexcept { return lanes_[lane]->sweep; }

 private:
  class FrameAdapter;
  // One LiDAR: its decoder and its sweep in progress, filtered against an ROI chain of its own
  // (several sensors' sweeps overlap in time: each is filtered against the chain placed at its
  // own start, for the robot's pose then).
  struct Lane {
    // LiDAR `i` of config.all_lidars().
    Lane(const DaemonConfig& config, std::size_t i, const pose::PoseBuffer& poses);
    DaemonConfig::Lidar lidar;
    std::size_t index = 0;  // in lidars:
    vlp16::StreamDecoder decoder;
    pose::FiringPoses firing;
    roi::RoiChain chain;
    Sweep sweep;
    bool in_sweep = false;
    std::size_t unfiltered_from = 0;  // the frame's points before this one are filtered
    Eigen::Isometry3d sweep_sensor_pose = Eigen::Isometry3d::Identity();
    std::uint32_t sender = 0;  // several LiDARs: sensor_address (host order; 0: any)
    double host_minus_lidar_utc_s = std::numeric_limits<double>::quiet_NaN();
  };
  void pose_message(std::span<const std::uint8_t> bytes);
  void start_sweep(Lane& lane, const vlp16::Frame& frame);
  // Projects the robot's position on the active trajectory (within the window after the last
  // sweep's projection, or anywhere after a jump) and places the lane's ROI chain there.
  void place_chain(Lane& lane, const Eigen::Vector2d& position);
  void add_points(Lane& lane, const vlp16::Frame& frame, std::size_t first, SweepSink& sink);
  void end_sweep(Lane& lane, const vlp16::Frame& frame, SweepSink& sink);
  // Filters the frame's points not filtered yet, in batches, while at least `at_least` wait.
  void filter_points(Lane& lane, const vlp16::Frame& frame, std::size_t at_least, SweepSink& sink);
  // Places points [first, end) of the frame in the global frame (one pose per firing, or the
  // sweep's), filters them in one scan and appends the kept ones. Answers kValid, or the
  // status of a firing whose pose was not valid (the sweep is then withheld).
  pose::PoseStatus filter_batch(Lane& lane, const vlp16::Frame& frame, std::size_t first, std::size_t end,
                                SweepSink& sink);
  // outputs.raw_points: one in outputs.raw_points_decimation of the batch's placed points
  // (scratch_), by their index in the frame, appended to the sweep's raw columns.
  void keep_raw(Lane& lane, const vlp16::Frame& frame, std::size_t first, std::size_t end);

  DaemonConfig config_;
  pose::PoseBuffer poses_;
  pose_input::PoseInput pose_input_;
  std::vector<std::unique_ptr<Lane>> lanes_;
  std::unique_ptr<SweepMerger> merger_;  // several LiDARs

  std::unique_ptr<ActiveTrajectory> active_;
  std::unique_ptr<ActiveTrajectory> pending_;
  std::unique_ptr<ActiveTrajectory> retired_;
  double s_hint_m_ = 0.0;
  double trajectory_distance_m_ = std::numeric_limits<double>::quiet_NaN();
  std::optional<std::int64_t> host_utc_offset_ns_;
  bool have_hint_ = false;
  std::optional<std::int64_t> valid_since_ns_;  // first sweep start of the current valid run

  std::vector<roi::PointXYZI> scratch_;  // one batch's points in the global frame
  roi::IndexVector kept_;
  std::int64_t arrival_ns_ = 0;
  std::int64_t now_ns_ = 0;
  bool keep_indices_ = false;
  ProcessorCounters counters_;
};

}  // namespace trajroi::pipeline
