#pragma once

// The status table: every counter trajroid reports, in one enum-indexed array with prefixed
// names ("ring_drops.lidar", "lidar.rejected.wrong_size", "pose.fixes", …). The processing
// thread fills a snapshot once a second (and a final one) for the publisher's status message.
#include <array>
#include <cstdint>
#include <string_view>

#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/pose/pose_buffer.hpp"
#include "trajroi/vlp16/packet.hpp"
#include "trajroi/vlp16/position.hpp"

namespace trajroi::daemon {

struct Pipeline;

// Every counter of the status table, once, in the message's order: X(id, name) is one counter;
// B(id, prefix, Enum, count) a block of one counter per value of a decoder's error enum (its
// kNone, value 0, omitted), each named prefix + the value's name. The enum and the names are
// both made from this list.
#define TRAJROI_STATUS_COUNTERS(X, B)                                                \
  X(kRingDropsLidar, "ring_drops.lidar")                                             \
  X(kRingDropsGnss, "ring_drops.gnss")                                               \
  X(kRingDropsImu, "ring_drops.imu")                                                 \
  X(kRingDropsSweeps, "ring_drops.sweeps")                                           \
  X(kRingDropsStatus, "ring_drops.status")                                           \
  X(kRingDropsTrajectory, "ring_drops.trajectory")                                   \
  X(kRingDropsRecord, "ring_drops.record")                                           \
  X(kLidarOversize, "lidar.oversize_datagrams")                                      \
  X(kLidarSourceErrors, "lidar.source_errors")                                       \
  X(kLidarRejectedSource, "lidar.rejected_source")                                   \
  X(kLidarKernelDrops, "lidar.kernel_drops")                                         \
  B(kLidarRejected, "lidar.rejected.", vlp16::PacketError, vlp16::kPacketErrorCount) \
  X(kLidarOutOfOrder, "lidar.out_of_order")                                          \
  X(kLidarRestarts, "lidar.restarts")                                                \
  X(kLidarLateDropped, "lidar.late_dropped")                                         \
  X(kLidarDuplicates, "lidar.duplicates")                                            \
  X(kLidarClockResets, "lidar.clock_resets")                                         \
  X(kLidarClockJumps, "lidar.clock_jumps")                                           \
  X(kLidarNoReturn, "lidar.no_return")                                               \
  X(kLidarOutOfRange, "lidar.out_of_range")                                          \
  X(kLidarPartialSweeps, "lidar.partial_sweeps")                                     \
  X(kLidarPositionWrongSize, "lidar.position_wrong_size")                            \
  B(kLidarNmea, "lidar.nmea.", vlp16::NmeaError, vlp16::kNmeaErrorCount)             \
  X(kGnssBytes, "gnss.bytes")                                                        \
  X(kGnssFrames, "gnss.frames")                                                      \
  X(kGnssSkippedBytes, "gnss.skipped_bytes")                                         \
  X(kGnssChecksumErrors, "gnss.checksum_errors")                                     \
  X(kGnssBadLengths, "gnss.bad_lengths")                                             \
  X(kImuBytes, "imu.bytes")                                                          \
  X(kImuFrames, "imu.frames")                                                        \
  X(kImuSkippedBytes, "imu.skipped_bytes")                                           \
  X(kImuChecksumErrors, "imu.checksum_errors")                                       \
  X(kImuBadLengths, "imu.bad_lengths")                                               \
  X(kSerialDisconnects, "serial.disconnects")                                        \
  X(kPoseFixes, "pose.fixes")                                                        \
  X(kPoseHighPrecisionFixes, "pose.high_precision_fixes")                            \
  X(kPoseInvalidPosition, "pose.invalid_position")                                   \
  X(kPoseMalformedMessages, "pose.malformed_messages")                               \
  X(kPoseAttitudes, "pose.attitudes")                                                \
  X(kPoseImuWithoutAttitude, "pose.imu_without_attitude")                            \
  X(kPoseImuReceiveStamped, "pose.imu_receive_stamped")                              \
  X(kPoseGnssHeadings, "pose.gnss_headings")                                         \
  X(kPoseUbxOther, "pose.ubx_other_messages")                                        \
  X(kGnssForeignFrames, "gnss.vn100_frames")                                         \
  X(kImuForeignFrames, "imu.ubx_frames")                                             \
  X(kPoseExternal, "pose.localization_poses")                                        \
  X(kPoseExternalInvalid, "pose.localization_invalid")                               \
  X(kPoseMessagesMalformed, "pose.localization_malformed")                           \
  X(kRingDropsPose, "ring_drops.pose_input")                                         \
  X(kPoseRefusedSamples, "pose.refused_samples")                                     \
  X(kPoseGnssClockResets, "pose.gnss_clock_resets")                                  \
  X(kPoseImuClockResets, "pose.imu_clock_resets")                                    \
  X(kSweepsPointsTruncated, "sweeps.points_truncated")                               \
  X(kTrajectorySwaps, "trajectory.swaps")                                            \
  X(kTrajectoryProjectionReacquired, "trajectory.projection_reacquired")             \
  X(kLidarDecodedAhead, "lidar.decoded_ahead")                                       \
  X(kLidarNotVlp16, "lidar.not_vlp16_datagrams")                                     \
  X(kGnssNmea, "gnss.nmea_sentences")                                                \
  X(kGnssVnAscii, "gnss.vn100_ascii_sentences")                                      \
  X(kGnssRtcm3, "gnss.rtcm3_frames")                                                 \
  X(kImuNmea, "imu.nmea_sentences")                                                  \
  X(kImuVnAscii, "imu.vn100_ascii_sentences")                                        \
  X(kImuRtcm3, "imu.rtcm3_frames")                                                   \
  X(kChronySamples, "time.chrony_samples")                                           \
  X(kMergePublished, "lidar_merge.published")                                        \
  X(kMergeIncomplete, "lidar_merge.incomplete")

enum class Counter : std::uint16_t {
#define TRAJROI_COUNTER_ID(id, name) id,
#define TRAJROI_COUNTER_BLOCK(id, prefix, Enum, count) id, id##Last_ = id + (count)-2,
  TRAJROI_STATUS_COUNTERS(TRAJROI_COUNTER_ID, TRAJROI_COUNTER_BLOCK)
#undef TRAJROI_COUNTER_ID
#undef TRAJROI_COUNTER_BLOCK
      kCount
};
inline constexpr std::size_t kCounterCount = static_cast<std::size_t>(Counter::kCount);

// The counter's name in the status message.
[[nodiscard]] std::string_view counter_name(std::size_t index) noexcept;
[[nodiscard]] inline std::string_view counter_name(Counter c) noexcept {
  return counter_name(static_cast<std::size_t>(c));
}

// The drops of every ring between the threads ("ring_drops.*"), in the table's order.
inline constexpr Counter kRingDropCounters[] = {
    Counter::kRingDropsLidar,  Counter::kRingDropsGnss,   Counter::kRingDropsImu,        Counter::kRingDropsPose,
    Counter::kRingDropsSweeps, Counter::kRingDropsStatus, Counter::kRingDropsTrajectory, Counter::kRingDropsRecord};

struct StatusSnapshot {
  std::int64_t steady_ns = 0;
  std::int32_t trajectory_id = 0;
  pipeline::ProcessorCounters processor;
  std::uint64_t lidar_packets = 0, position_packets = 0, lost_packets = 0, decode_errors = 0;
  // Several LiDARs: bit i set while sensor i (lidars:) has given no sweep for lidar_merge.silent_s.
  std::uint32_t silent_lidars = 0;
  // The pose at the newest sweep, or at the newest input when no sweep came in the last second
  // (so that the pose inputs' state shows without LiDAR data), with the failed gate's figures.
  bool pose_valid = false;
  pose::PoseStatus pose_status = pose::PoseStatus::kNoGnss;
  double pose_measured = 0.0, pose_limit = 0.0;
  double pose_age_s = -1.0;      // newest input − newest fix or localization pose (−1: none)
  double attitude_age_s = -1.0;  // newest input − newest attitude (−1: none)
  std::uint8_t fix_type = 0;
  double h_acc_m = 0.0;
  std::int8_t rtk = -1;  // newest NAV-PVT's carrier solution (pose::RtkSolution), -1: none yet
  std::string_view heading_source = "none";
  std::uint8_t closed_streams = 0;  // bit 1 << inputs::Stream: a serial device not open now
  // The LiDAR data port's datagrams that are not VLP-16 packets: sizes and first senders.
  std::uint32_t foreign_min_size = 0, foreign_max_size = 0;
  std::array<std::uint64_t, 4> foreign_senders{};  // IPv4 << 16 | port; 0: none
  std::uint64_t foreign_from_others = 0;
  bool final = false;  // the last one: the input has ended
  // For the fault lines (health.hpp): the robot's distance to the active trajectory at the
  // last sweep with a pose (NaN before), the host clock's offsets.
  double trajectory_distance_m = 0.0;
  double host_minus_gnss_utc_s = 0.0;  // NaN: unknown
  double gnss_time_accuracy_s = 0.0;   // its NAV-PVT tAcc (NaN: unknown)
  // Each LiDAR's own (its index in lidars:; the first is the single lidar:'s), for the lines
  // that name one sensor: its model, its clock and PPS, its packets.
  struct LidarFacts {
    double host_minus_utc_s = 0.0;         // host UTC − its PPS-locked UTC (NaN: unknown)
    std::int8_t model = -1;                // vlp16::Model of the packets decoded, -1: none yet
    std::int8_t pps_status = -1;           // vlp16::PpsStatus of the newest position packet, -1: none
    std::int8_t gprmc_valid = -1;          // its RMC: 1 valid, 0 not, -1 none
    std::uint64_t accepted = 0;            // data packets decoded (not rejected)
    std::uint64_t unsupported = 0;         // data packets rejected for their model
    std::array<char, 256> model_reason{};  // the model check's last rejection ("" if none)
  };
  std::array<LidarFacts, kMaxLidars> lidar{};
  std::size_t lidar_count = 1;
  std::array<std::uint64_t, kCounterCount> counters{};

  [[nodiscard]] std::uint64_t& operator[](Counter c) noexcept { return counters[static_cast<std::size_t>(c)]; }
  [[nodiscard]] std::uint64_t operator[](Counter c) const noexcept { return counters[static_cast<std::size_t>(c)]; }
  // Every ring's drops together.
  [[nodiscard]] std::uint64_t ring_drops() const noexcept;
};

// Fills `s` from the processor (processing thread) and the pipeline's rings and inputs.
void fill_snapshot(const pipeline::SweepProcessor& processor, const Pipeline& pipeline, std::int64_t last_receive_ns,
                   bool final, StatusSnapshot& s);

}  // namespace trajroi::daemon
