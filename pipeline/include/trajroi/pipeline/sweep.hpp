#pragma once

// A sweep as the per-sweep pipeline hands it on: its header (time, pose, the ROI chain it was
// filtered against) and its kept points in the global frame, structure of arrays; and the sink
// that takes it.
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "trajroi/pose/pose_buffer.hpp"
#include "trajroi/roi/centres.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/trajectory.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::pipeline {

using roi::RoiShape;

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

  // Several LiDARs (lidars:): bit i set when sensor i's points are in this sweep (0: the one
  // LiDAR of lidar:); `missing` those the merge waited for and did not get.
  std::uint32_t sensors = 0;
  std::uint32_t missing = 0;
  std::uint32_t silent = 0;  // those silent (no sweep for lidar_merge.silent_s) as it went out

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
  // Several LiDARs merged: how long (input time) the window stayed open after the last sweep
  // that joined it, waiting for sensors whose sweeps did not come (lidar_merge.max_wait_s); 0
  // when it went out as its last sweep joined, and for one LiDAR.
  std::int64_t merge_wait_ns = 0;
};

// Points in the global frame as a structure of arrays (the columns of points_t).
struct PointColumns {
  // Grown by resize() and then written: its new elements are left unwritten, not zeroed.
  template <typename T>
  using Array = std::vector<T, roi::DefaultInitAllocator<T>>;
  Array<float> x, y, z;
  Array<std::uint8_t> intensity, ring, return_type;
  Array<std::int32_t> time_offset_ns;

  // Points of the arrays' capacity known to be resident (make_resident, make_resident_to).
  std::size_t resident = 0;

  void reserve(std::size_t points);
  // Exchanges the arrays (their capacity and residence go with them: nothing allocated,
  // nothing copied).
  void swap(PointColumns& other) noexcept;
  // Makes the arrays' whole capacity resident (one madvise each, not a page fault per page).
  void make_resident();
  // Makes room for `points` resident before the arrays grow to it, at least kResidentStep
  // points at a time (a sweep that was not made resident, in an as-fast replay, becomes so as
  // it fills: a few system calls instead of a page fault per page, 10 µs each on a VM).
  void make_resident_to(std::size_t points);
  static constexpr std::size_t kResidentStep = 16384;
  void clear() noexcept;
  [[nodiscard]] std::size_t size() const noexcept { return x.size(); }
};

struct Sweep : SweepHeader, PointColumns {
  // The columns are the kept points. With SweepProcessor::keep_point_indices(): each kept
  // point's index among the decoded sweep's points (vlp16::Frame::points), for scoring against
  // per-point truth.
  Array<std::uint32_t> point_index;
  // Several LiDARs: the sensor (its index in lidars:) of each kept point; empty for one LiDAR.
  Array<std::uint8_t> sensor_index;
  // With outputs.raw_points: every decoded point of the sweep placed in the global frame,
  // before the ROI, one in outputs.raw_points_decimation (by its index in the sweep); empty
  // otherwise, and for a sweep without a valid pose.
  PointColumns raw;
  // Several LiDARs: the sensor of each raw point, as sensor_index; empty for one LiDAR.
  Array<std::uint8_t> raw_sensor_index;

  // Becomes `other`: its header copied, its points taken by exchanging arrays, so that
  // `other` is left with this sweep's arrays (their capacity: nothing is allocated, nothing
  // copied, when both were reserved alike) and its points are to be cleared. The point
  // indices are copied.
  void take(Sweep& other);
  // `raw_points`: room for the decimated decoded points (0: none).
  void reserve(std::size_t points, std::size_t centres, std::size_t raw_points = 0);
  // Empties the sweep and writes a page of its arrays' capacity at a time, so that the reserved
  // memory is resident: a sweep larger than any before it then takes no page fault, and a
  // flood or a busier scene does not grow the resident memory.
  void make_resident();
  // PointColumns::make_resident_to, the sensor indices too.
  void make_resident_to(std::size_t points);
  void clear_points() noexcept;
};

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

}  // namespace trajroi::pipeline
