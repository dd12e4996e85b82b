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

// Ranges of the decoders' own error enums sit in the table as blocks (their kNone omitted).
enum class Counter : std::uint16_t {
  kRingDropsLidar,
  kRingDropsGnss,
  kRingDropsImu,
  kRingDropsSweeps,
  kRingDropsStatus,
  kRingDropsTrajectory,
  kRingDropsRecord,
  kLidarOversize,
  kLidarSourceErrors,
  kLidarRejectedSource,
  kLidarKernelDrops,
  kLidarRejected,  // + PacketError − 1
  kLidarOutOfOrder = kLidarRejected + vlp16::kPacketErrorCount - 1,
  kLidarRestarts,
  kLidarLateDropped,
  kLidarDuplicates,
  kLidarClockResets,
  kLidarClockJumps,
  kLidarNoReturn,
  kLidarOutOfRange,
  kLidarPartialSweeps,
  kLidarPositionWrongSize,
  kLidarNmea,  // + NmeaError − 1
  kGnssBytes = kLidarNmea + vlp16::kNmeaErrorCount - 1,
  kGnssFrames,
  kGnssSkippedBytes,
  kGnssChecksumErrors,
  kGnssBadLengths,
  kImuBytes,
  kImuFrames,
  kImuSkippedBytes,
  kImuChecksumErrors,
  kImuBadLengths,
  kSerialDisconnects,
  kPoseFixes,
  kPoseHighPrecisionFixes,
  kPoseInvalidPosition,
  kPoseMalformedMessages,
  kPoseAttitudes,
  kPoseImuWithoutAttitude,
  kPoseImuReceiveStamped,
  kPoseGnssHeadings,
  kPoseUbxOther,
  kGnssForeignFrames,
  kImuForeignFrames,
  kPoseExternal,
  kPoseExternalInvalid,
  kPoseMessagesMalformed,
  kRingDropsPose,
  kPoseRefusedSamples,
  kPoseGnssClockResets,
  kPoseImuClockResets,
  kSweepsPointsTruncated,
  kTrajectorySwaps,
  kTrajectoryProjectionReacquired,
  kLidarDecodedAhead,
  kCount
};
inline constexpr std::size_t kCounterCount = static_cast<std::size_t>(Counter::kCount);

// The counter's name in the status message.
[[nodiscard]] std::string_view counter_name(std::size_t index) noexcept;

struct StatusSnapshot {
  std::int64_t steady_ns = 0;
  std::int32_t trajectory_id = 0;
  pipeline::ProcessorCounters processor;
  std::uint64_t lidar_packets = 0, position_packets = 0, lost_packets = 0, decode_errors = 0;
  bool pose_valid = false;
  pose::PoseStatus pose_status = pose::PoseStatus::kNoGnss;
  double pose_age_s = -1.0;
  std::uint8_t fix_type = 0;
  double h_acc_m = 0.0;
  bool final = false;  // the last one: the input has ended
  // For the fault lines (health.hpp): the robot's distance to the active trajectory at the
  // last sweep with a pose (NaN before), and the model check's last rejection ("" if none).
  double trajectory_distance_m = 0.0;
  double host_minus_gnss_utc_s = 0.0;  // NaN: unknown
  std::int8_t lidar_pps_status = -1;   // vlp16::PpsStatus of the newest position packet, -1: none
  std::int8_t lidar_gprmc_valid = -1;  // its RMC: 1 valid, 0 not, -1 none
  std::array<char, 160> model_reason{};
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
