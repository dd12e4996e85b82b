#pragma once

// The processing thread's work, without the thread: lidar datagrams and GNSS / IMU bytes in
// (each with its host receive time), filtered sweeps out. Pure and deterministic: the same
// inputs in the same order give the same sweeps, which is what makes a replay exact and what
// the tests drive directly.
//
// Per packet, as it arrives: decode (vlp16::StreamDecoder) → the sensor's pose at each
// firing's time (pose::FiringPoses, or one pose for the sweep) → transform into the global
// frame → ROI membership (roi::GridFilter, exact) → append the kept points to the sweep. At a
// sweep's first packet the ROI chain is placed: centres every d from the robot's projection
// on the active trajectory over the look-ahead (growing with speed when configured); a new
// trajectory offered in between is swapped in there, never inside a sweep. At the sweep's
// end the sweep goes to the SweepSink.
//
// No allocation once warm: every buffer is sized at construction (points per sweep up to
// buffers.max_points_per_sweep; more are counted as truncated) and reused.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "trajroi/daemon/config.hpp"
#include "trajroi/pose/pose_buffer.hpp"
#include "trajroi/pose_input/pose_input.hpp"
#include "trajroi/roi/centres.hpp"
#include "trajroi/roi/filter_stats.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/trajectory.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::daemon {

// A trajectory with the id it is published under (0: the configured file's).
struct ActiveTrajectory {
  roi::Trajectory trajectory;
  std::int32_t id = 0;
};

// Sensor or robot pose as published: translation and unit quaternion (w, x, y, z). The
// isometry the daemon computes with is rebuilt from exactly these numbers, so a consumer that
// rebuilds it the same way (Quaterniond(w, x, y, z).toRotationMatrix()) transforms
// bit-identically.
struct PublishedPose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  [[nodiscard]] static PublishedPose from(const Eigen::Isometry3d& pose);
  [[nodiscard]] Eigen::Isometry3d isometry() const;
};

// A sweep's description: everything but its kept points.
struct SweepHeader {
  std::uint64_t index = 0;
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  bool partial = false;
  std::uint8_t return_mode = 0;
  std::uint32_t points_in = 0;
  std::uint32_t lost_packets = 0;
  std::uint32_t truncated = 0;  // kept points beyond the buffer

  // The pose: `filtered` only when it was valid for every point.
  bool filtered = false;
  pose::PoseStatus pose_status = pose::PoseStatus::kNoGnss;
  double pose_measured = 0.0, pose_limit = 0.0;  // the failing figure and its limit (PoseQuery)
  std::string_view heading_source = "none";      // where the attitude came from (static text)
  // The sweep's start in UTC (ns since 1970; 0: unknown) and where that came from: "vlp16_pps"
  // (the sensor's PPS-locked clock, its position packets with a valid RMC), "host" (the host's
  // CLOCK_REALTIME, live), "none" (a replay without a PPS-locked sensor).
  std::int64_t start_utc_ns = 0;
  std::string_view time_source = "none";
  std::int64_t pose_t_ns = 0;  // sweep start
  PublishedPose robot;         // global_from_robot at the start
  PublishedPose sensor;        // global_from_lidar at the start (used for the whole
                               // sweep in per-sweep mode)
  double speed_mps = 0.0;      // over the last 0.5 s (0.2 s, 0.1 s after a pose gap)
  bool speed_known = false;    // false: the pose valid for less than 0.1 s (speed_mps 0)
  pose::FixQuality fix;        // newest fix at the sweep's start
  std::int64_t fix_t_ns = 0;   // its time (0: none)

  // The ROI chain.
  std::int32_t trajectory_id = 0;
  RoiShape shape = RoiShape::kCircular;
  double radius_m = 0.0, height_m = 0.0, width_m = 0.0, spacing_m = 0.0;
  double start_s_m = 0.0, look_ahead_m = 0.0;
  std::vector<roi::Centre> centres;

  // Steady-clock bookkeeping: when the last datagram with points of this sweep arrived (set
  // from set_input_arrival), and the processing time the wiring measured.
  std::int64_t last_packet_arrival_ns = 0;
  std::int64_t processing_ns = 0;
  // Set by the wiring as it hands the sweep over: when the processing of the packet that
  // closed it began, and when it went to the publisher (a late sweep's log line says where
  // its time went).
  std::int64_t closing_packet_start_ns = 0;
  std::int64_t handed_over_ns = 0;
};

struct Sweep : SweepHeader {
  // Grown by resize() and then written: its new elements are left unwritten, not zeroed.
  template <typename T>
  using Array = std::vector<T, roi::DefaultInitAllocator<T>>;
  // Kept points, global frame, structure of arrays.
  Array<float> x, y, z;
  Array<std::uint8_t> intensity, ring, return_type;
  Array<std::int32_t> time_offset_ns;
  // With SweepProcessor::keep_point_indices(): each kept point's index among the decoded
  // sweep's points (vlp16::Frame::points), for scoring against per-point truth.
  Array<std::uint32_t> point_index;

  // Becomes `other`: its header copied, its kept points taken by exchanging arrays, so that
  // `other` is left with this sweep's arrays (their capacity: nothing is allocated, nothing
  // copied, when both were reserved alike) and its points are to be cleared. The point
  // indices are copied.
  void take(Sweep& other);
  void reserve(std::size_t points, std::size_t centres);
  // Empties the sweep and writes a page of its arrays' capacity at a time, so that the reserved
  // memory is resident: a sweep larger than any before it then takes no page fault, and a
  // flood or a busier scene does not grow the resident memory.
  void make_resident();
  void clear_points() noexcept;
  [[nodiscard]] std::size_t size() const noexcept { return x.size(); }
};

enum class LidarPort : std::uint8_t { kData, kPosition };

class SweepSink {
 public:
  virtual ~SweepSink() = default;
  // `sweep` is valid during the call only; the sink may take its points (Sweep::take).
  virtual void on_sweep(Sweep& sweep) = 0;
  // Every run of points as placed in the global frame, before the ROI: `placed[k]` is the
  // frame's point `first + k`. Only while the sweep's pose is valid. For the evaluations.
  virtual void on_placed(const vlp16::Frame& /*frame*/, std::size_t /*first*/,
                         std::span<const roi::PointXYZI> /*placed*/) {}
};

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
};

// How the configuration sets up the pose input (IMU mounting and declination, the delays).
[[nodiscard]] pose_input::PoseInputConfig pose_input_config(const DaemonConfig& config);

class SweepProcessor {
 public:
  SweepProcessor(const DaemonConfig& config, std::unique_ptr<ActiveTrajectory> trajectory);
  ~SweepProcessor();

  // Times the ROI filter's scans for the configured shape on its start-up grid and makes
  // the fastest on this machine the one used (roi::GridFilter::calibrate); at start, before
  // the first sweep.
  roi::ScanCalibration calibrate_scan() const;
  // Makes the sweep it fills resident (Sweep::make_resident); at start, before the first
  // datagram.
  void make_resident() { sweep_.make_resident(); }

  // `decoded`: a data packet's points decoded ahead by packet_decoder() (vlp16::StreamDecoder::
  // on_data_packet), or null.
  void lidar_datagram(LidarPort port, std::span<const std::uint8_t> payload, std::int64_t receive_ns, SweepSink& sink,
                      const vlp16::DecodedPacket* decoded = nullptr);
  // The packet decoder the stream decodes with: const and stateless, for another thread to
  // decode packets ahead.
  [[nodiscard]] const vlp16::PacketDecoder& packet_decoder() const noexcept { return decoder_.decoder(); }
  void gnss_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
    pose_input_.gnss_bytes(bytes, receive_ns);
  }
  void imu_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
    pose_input_.imu_bytes(bytes, receive_ns);
  }
  // A pose_input_t from the robot's localization (pose.source lcm) as its input hands it over:
  // 8 bytes of (CLOCK_REALTIME − CLOCK_MONOTONIC) at its receipt, little-endian, then the LCM
  // message. A message that does not decode is counted.
  void pose_message(std::span<const std::uint8_t> bytes, std::int64_t receive_ns);
  // Steady-clock time the next datagram entered the daemon: a sweep keeps that of the last
  // datagram that gave it points (for the latency figures; no effect on the output).
  void set_input_arrival(std::int64_t steady_ns) noexcept { arrival_ns_ = steady_ns; }
  // Live: the host's CLOCK_REALTIME − CLOCK_MONOTONIC now (refreshed each second), for the
  // sweeps' UTC and the host clock's offset from GNSS time. Unset in a replay.
  void set_host_utc_offset(std::optional<std::int64_t> offset_ns) noexcept { host_utc_offset_ns_ = offset_ns; }
  // Host UTC − GNSS UTC at the newest GNSS epoch with a valid time, s (NaN: not both known).
  [[nodiscard]] double host_minus_gnss_utc_s() const noexcept;
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

  [[nodiscard]] const ProcessorCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const vlp16::StreamCounters& lidar_counters() const noexcept { return decoder_.counters(); }
  [[nodiscard]] const std::optional<vlp16::PositionPacket>& lidar_position() const noexcept {
    return decoder_.last_position();
  }
  [[nodiscard]] const pose_input::PoseInput& pose_input() const noexcept { return pose_input_; }
  [[nodiscard]] const pose::PoseBuffer& poses() const noexcept { return poses_; }
  // The robot's distance to the active trajectory at the last sweep with a pose (NaN before).
  [[nodiscard]] double trajectory_distance_m() const noexcept { return trajectory_distance_m_; }
  // Why the last packet rejected for its model was ("product id 0x28 (VLP-32C) is not
  // supported"), empty if none was.
  [[nodiscard]] const std::string& lidar_model_reason() const noexcept { return decoder_.model_check().reason(); }
  // The sweep being built (its pose status tells why a sweep is withheld).
  [[nodiscard]] const Sweep& current() const noexcept { return sweep_; }

 private:
  class FrameAdapter;
  void start_sweep(const vlp16::Frame& frame);
  void add_points(const vlp16::Frame& frame, std::size_t first, SweepSink& sink);
  void end_sweep(const vlp16::Frame& frame, SweepSink& sink);
  // Filters the frame's points not filtered yet, in batches, while at least `at_least` wait.
  void filter_points(const vlp16::Frame& frame, std::size_t at_least, SweepSink& sink);
  // Places points [first, end) of the frame in the global frame (one pose per firing, or the
  // sweep's), filters them in one scan and appends the kept ones. Answers kValid, or the
  // status of a firing whose pose was not valid (the sweep is then withheld).
  pose::PoseStatus filter_batch(const vlp16::Frame& frame, std::size_t first, std::size_t end, SweepSink& sink);

  DaemonConfig config_;
  vlp16::StreamDecoder decoder_;
  pose::PoseBuffer poses_;
  pose_input::PoseInput pose_input_;
  pose::FiringPoses firing_;

  std::unique_ptr<ActiveTrajectory> active_;
  std::unique_ptr<ActiveTrajectory> pending_;
  std::unique_ptr<ActiveTrajectory> retired_;
  double s_hint_m_ = 0.0;
  double trajectory_distance_m_ = std::numeric_limits<double>::quiet_NaN();
  std::optional<std::int64_t> host_utc_offset_ns_;
  bool have_hint_ = false;
  std::optional<std::int64_t> valid_since_ns_;  // first sweep start of the current valid run

  roi::CircularRoiSet circles_;
  roi::RectangularRoiSet rects_;
  roi::GridFilter<roi::CircularRoiSet> circle_grid_;
  roi::GridFilter<roi::RectangularRoiSet> rect_grid_;

  Sweep sweep_;
  bool in_sweep_ = false;
  std::size_t unfiltered_from_ = 0;  // the frame's points before this one are filtered
  Eigen::Isometry3d sweep_sensor_pose_ = Eigen::Isometry3d::Identity();
  std::vector<roi::PointXYZI> scratch_;  // one batch's points in the global frame
  roi::IndexVector kept_;
  std::int64_t arrival_ns_ = 0;
  bool keep_indices_ = false;
  ProcessorCounters counters_;
};

}  // namespace trajroi::daemon
