#include "status.hpp"

#include <algorithm>
#include <string>

#include "chrony_shm.hpp"
#include "pipeline.hpp"

namespace trajroi::daemon {
namespace {

using C = Counter;

constexpr std::size_t at(Counter c) {
  return static_cast<std::size_t>(c);
}

// Names, built once from the list: a block's names from its decoder's enum.
struct Names {
  std::array<std::string, kCounterCount> name;
  Names() {
#define TRAJROI_COUNTER_NAME(id, text) name[at(C::id)] = text;
#define TRAJROI_COUNTER_BLOCK_NAMES(id, prefix, Enum, count)                                \
  for (std::size_t e = 1; e < (count); ++e) {                                               \
    name[at(C::id) + e - 1] = prefix + std::string(vlp16::to_string(static_cast<Enum>(e))); \
  }
    TRAJROI_STATUS_COUNTERS(TRAJROI_COUNTER_NAME, TRAJROI_COUNTER_BLOCK_NAMES)
#undef TRAJROI_COUNTER_NAME
#undef TRAJROI_COUNTER_BLOCK_NAMES
  }
};

const Names& names() {
  static const Names n;
  return n;
}

void fill_lidar_facts(const pipeline::SweepProcessor& p, std::size_t lane, StatusSnapshot::LidarFacts& f) {
  f.host_minus_utc_s = p.host_minus_lidar_utc_s(lane);
  const vlp16::ModelCheck& model = p.lidar_stream(lane).model_check();
  f.model = model.decided() ? static_cast<std::int8_t>(model.model()) : std::int8_t{-1};
  const auto& position = p.lidar_position(lane);
  f.pps_status = position ? static_cast<std::int8_t>(position->pps) : std::int8_t{-1};
  f.gprmc_valid = !position || position->nmea != vlp16::NmeaError::kNone ? std::int8_t{-1}
                  : position->rmc.valid                                  ? std::int8_t{1}
                                                                         : std::int8_t{0};
  const vlp16::StreamCounters& c = p.lidar_counters(lane);
  f.accepted = c.data_packets - c.rejected_total();
  f.unsupported = c.rejected[static_cast<std::size_t>(vlp16::PacketError::kUnsupportedProduct)];
  const std::string& reason = p.lidar_model_reason(lane);
  const std::size_t n = std::min(reason.size(), f.model_reason.size() - 1);
  std::copy_n(reason.begin(), n, f.model_reason.begin());
  f.model_reason[n] = '\0';
}

}  // namespace

std::string_view counter_name(std::size_t index) noexcept {
  return index < kCounterCount ? std::string_view(names().name[index]) : std::string_view("?");
}

std::uint64_t StatusSnapshot::ring_drops() const noexcept {
  std::uint64_t drops = 0;
  for (const Counter c : kRingDropCounters)
    drops += (*this)[c];
  return drops;
}

void fill_snapshot(const pipeline::SweepProcessor& p, const Pipeline& pipeline, std::int64_t last_receive_ns,
                   bool final, StatusSnapshot& s) {
  // Every LiDAR's counts together; what names one sensor, each one's.
  vlp16::StreamCounters l = p.lidar_counters();
  for (std::size_t i = 1; i < p.lane_count(); ++i)
    l += p.lidar_counters(i);
  s.steady_ns = host::monotonic_ns();
  s.final = final;
  s.trajectory_id = p.active_trajectory_id();
  s.processor = p.counters();
  s.lidar_packets = l.data_packets;
  s.position_packets = l.position_packets;
  s.lost_packets = l.lost_packets;
  s.decode_errors = l.rejected_total();
  s.silent_lidars = 0;
  s.lidar_count = std::min(p.lane_count(), s.lidar.size());
  for (std::size_t i = 0; i < s.lidar_count; ++i)
    fill_lidar_facts(p, i, s.lidar[i]);
  if (const pipeline::SweepMerger* merger = p.merger(); merger != nullptr) {
    for (std::size_t i = 0; i < p.lane_count(); ++i) {
      if (merger->silent(i, p.input_time_ns())) s.silent_lidars |= 1U << i;
    }
  }
  const pipeline::Sweep& current = p.current();
  constexpr std::int64_t kRecent_ns = 1'000'000'000;
  if (p.counters().sweeps > 0 && last_receive_ns - current.start_ns < kRecent_ns) {
    s.pose_status = current.pose_status;
    s.pose_measured = current.pose_measured;
    s.pose_limit = current.pose_limit;
  } else {  // no sweep lately: the pose inputs' state at the newest input
    const pose::PoseQuery q = p.poses().pose_at(last_receive_ns);
    s.pose_status = q.status;
    s.pose_measured = q.measured;
    s.pose_limit = q.limit;
  }
  s.pose_valid = s.pose_status == pose::PoseStatus::kValid;
  s.heading_source = pipeline.config.pose_source == PoseSource::kFixed
                         ? std::string_view("fixed")
                         : pose_input::to_string(p.pose_input().heading_source());
  const auto attitude_ns = p.poses().newest_attitude_ns();
  s.attitude_age_s = attitude_ns ? std::max(0.0, static_cast<double>(last_receive_ns - *attitude_ns) * 1e-9) : -1.0;
  const pose::GnssFix* fix = p.poses().newest_fix();
  // Against the newest input's receive time (a replay's clock, not the wall's); a fix stamped
  // after it (the delay configured too small) is not older than the input: age 0.
  s.pose_age_s = fix != nullptr ? std::max(0.0, static_cast<double>(last_receive_ns - fix->t_ns) * 1e-9) : -1.0;
  s.fix_type = fix != nullptr ? fix->quality.fix_type : 0;
  s.h_acc_m = fix != nullptr ? fix->quality.h_acc_m : 0.0;
  s.trajectory_distance_m = p.trajectory_distance_m();
  s.host_minus_gnss_utc_s = p.host_minus_gnss_utc_s();
  s.gnss_time_accuracy_s = p.gnss_time_accuracy_s();
  if (const auto& pvt = p.pose_input().newest_pvt()) {
    s.rtk = static_cast<std::int8_t>(pvt->carr_soln == ublox::CarrierSolution::kFixed   ? pose::RtkSolution::kFixed
                                     : pvt->carr_soln == ublox::CarrierSolution::kFloat ? pose::RtkSolution::kFloat
                                                                                        : pose::RtkSolution::kNone);
  } else {
    s.rtk = -1;
  }

  s.counters.fill(0);
  s.closed_streams = 0;
  s.foreign_min_size = ~0U;
  s.foreign_max_size = 0;
  s.foreign_senders.fill(0);
  s.foreign_from_others = 0;
  for (const auto& lane : pipeline.inputs) {
    s.closed_streams |= lane->closed_streams.load(std::memory_order_relaxed);
    const ForeignDatagrams& f = lane->foreign;
    if (const std::uint64_t count = f.count.load(std::memory_order_relaxed); count > 0) {
      s[C::kLidarNotVlp16] += count;
      s.foreign_min_size = std::min(s.foreign_min_size, f.min_size.load(std::memory_order_relaxed));
      s.foreign_max_size = std::max(s.foreign_max_size, f.max_size.load(std::memory_order_relaxed));
      for (std::size_t i = 0; i < s.foreign_senders.size(); ++i)
        s.foreign_senders[i] = f.senders[i].load(std::memory_order_relaxed);
      s.foreign_from_others += f.from_others.load(std::memory_order_relaxed);
    }
    const auto drops = [&lane](inputs::Stream st) { return lane->ring->dropped(static_cast<std::size_t>(st)); };
    s[C::kRingDropsLidar] += drops(inputs::Stream::kLidarData) + drops(inputs::Stream::kLidarPosition);
    s[C::kRingDropsGnss] += drops(inputs::Stream::kGnss);
    s[C::kRingDropsImu] += drops(inputs::Stream::kImu);
    s[C::kRingDropsPose] += drops(inputs::Stream::kPose);
    s[C::kLidarOversize] += lane->oversize.load(std::memory_order_relaxed);
    s[C::kLidarRejectedSource] += lane->rejected_sources.load(std::memory_order_relaxed);
    s[C::kLidarKernelDrops] += lane->kernel_drops.load(std::memory_order_relaxed);
    s[C::kSerialDisconnects] += lane->disconnects.load(std::memory_order_relaxed);
    s[C::kLidarSourceErrors] += lane->errors.load(std::memory_order_relaxed);
  }
  // Several LiDARs on one port: a sender that is none of theirs, dropped by the processor.
  s[C::kLidarRejectedSource] += p.counters().lidar_unknown_sender;
  if (const pipeline::SweepMerger* merger = p.merger(); merger != nullptr) {
    s[C::kMergePublished] = merger->published();
    s[C::kMergeIncomplete] = merger->incomplete();
  }
  s[C::kChronySamples] = pipeline.chrony ? pipeline.chrony->samples() : 0;
  s[C::kRingDropsSweeps] = pipeline.sweeps.dropped();
  s[C::kRingDropsStatus] = pipeline.status->dropped();
  s[C::kRingDropsTrajectory] = pipeline.trajectories_in.dropped();
  s[C::kRingDropsRecord] = pipeline.record ? pipeline.record->dropped() : 0;
  for (std::size_t e = 1; e < vlp16::kPacketErrorCount; ++e)
    s.counters[at(C::kLidarRejected) + e - 1] = l.rejected[e];
  s[C::kLidarOutOfOrder] = l.out_of_order;
  s[C::kLidarRestarts] = l.restarts;
  s[C::kLidarLateDropped] = l.late_dropped;
  s[C::kLidarDuplicates] = l.duplicates;
  s[C::kLidarClockResets] = l.clock_resets;
  s[C::kLidarClockJumps] = l.clock_jumps;
  s[C::kLidarNoReturn] = l.no_return;
  s[C::kLidarOutOfRange] = l.out_of_range;
  s[C::kLidarPartialSweeps] = l.partial_frames;
  s[C::kLidarPositionWrongSize] = l.position_wrong_size;
  for (std::size_t e = 1; e < vlp16::kNmeaErrorCount; ++e)
    s.counters[at(C::kLidarNmea) + e - 1] = l.nmea[e];
  const pose_input::PoseInput& in = p.pose_input();
  const auto framing = [&s](Counter first, const framing::FramerCounters& f) {
    s.counters[at(first)] = f.bytes;
    s.counters[at(first) + 1] = f.frames;
    s.counters[at(first) + 2] = f.skipped_bytes;
    s.counters[at(first) + 3] = f.checksum_errors;
    s.counters[at(first) + 4] = f.bad_lengths + f.unsizable;
  };
  framing(C::kGnssBytes, in.gnss_framing());
  framing(C::kImuBytes, in.imu_framing());
  const pose_input::PoseInputCounters& pc = in.counters();
  s[C::kPoseFixes] = pc.fixes;
  s[C::kPoseHighPrecisionFixes] = pc.high_precision;
  s[C::kPoseInvalidPosition] = pc.invalid_position;
  s[C::kPoseMalformedMessages] = pc.malformed;
  s[C::kPoseAttitudes] = pc.attitudes;
  s[C::kPoseImuWithoutAttitude] = pc.imu_without_attitude;
  s[C::kPoseImuReceiveStamped] = pc.imu_receive_stamped;
  s[C::kPoseGnssHeadings] = pc.gnss_headings;
  s[C::kPoseUbxOther] = pc.ubx_other;
  s[C::kGnssForeignFrames] = pc.vn100_frames_on_gnss;
  s[C::kImuForeignFrames] = pc.ubx_frames_on_imu;
  s[C::kPoseExternal] = pc.external_poses;
  s[C::kPoseExternalInvalid] = pc.external_invalid;
  s[C::kPoseMessagesMalformed] = p.counters().pose_messages_malformed;
  s[C::kPoseRefusedSamples] = pc.refused;
  s[C::kPoseGnssClockResets] = in.gnss_clock().resets();
  s[C::kPoseImuClockResets] = in.imu_clock().resets();
  s[C::kSweepsPointsTruncated] = p.counters().points_truncated;
  s[C::kTrajectorySwaps] = p.counters().trajectory_swaps;
  s[C::kTrajectoryProjectionReacquired] = p.counters().projection_reacquired;
  s[C::kLidarDecodedAhead] = l.decoded_ahead;
  const auto sniffed = [&s](Counter first, const framing::SnifferCounters& c) {
    s.counters[at(first)] = c.nmea_sentences;
    s.counters[at(first) + 1] = c.vn100_ascii_sentences;
    s.counters[at(first) + 2] = c.rtcm3_frames;
  };
  sniffed(C::kGnssNmea, in.gnss_sniffed());
  sniffed(C::kImuNmea, in.imu_sniffed());
}

}  // namespace trajroi::daemon
