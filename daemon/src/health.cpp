#include "health.hpp"

#include <cmath>
#include <cstdio>

#include "trajroi/vlp16/packet.hpp"

namespace trajroi::daemon {

namespace {

using C = Counter;

std::string format(const char* pattern, auto... args) {
  char text[512];
  std::snprintf(text, sizeof text, pattern, args...);
  return text;
}

}  // namespace

HealthMonitor::HealthMonitor(const DaemonConfig& config, bool live, std::int64_t start_steady_ns)
    : config_(config), live_(live) {
  StatusSnapshot start;  // every counter starts at zero
  start.steady_ns = start_steady_ns;
  history_.push_back(start);
}

void HealthMonitor::set(Fault fault, bool active, std::string warning, std::string ended,
                        std::vector<HealthLine>& out) {
  if (active && !active_[fault]) out.push_back({HealthLine::Level::kWarning, std::move(warning)});
  if (!active && active_[fault] && !ended.empty()) out.push_back({HealthLine::Level::kInfo, std::move(ended)});
  active_[fault] = active;
}

std::vector<HealthLine> HealthMonitor::update(const StatusSnapshot& s) {
  std::vector<HealthLine> out;
  const StatusSnapshot previous = history_.back();
  history_.push_back(s);
  while (history_.size() > 2 && s.steady_ns - history_[1].steady_ns >= kWindow_ns)
    history_.pop_front();
  const StatusSnapshot& base = history_.front();
  const double window_s = static_cast<double>(s.steady_ns - base.steady_ns) * 1e-9;
  const bool judged = s.steady_ns - base.steady_ns >= kWindow_ns;  // enough history for "nothing came"
  const auto delta = [&](C c) { return s[c] - base[c]; };
  const auto step = [&](C c) { return s[c] - previous[c]; };
  const auto rejected = [&](vlp16::PacketError e) {
    return s.counters[static_cast<std::size_t>(C::kLidarRejected) + static_cast<std::size_t>(e) - 1];
  };
  const auto rejected_before = [&](vlp16::PacketError e) {
    return previous.counters[static_cast<std::size_t>(C::kLidarRejected) + static_cast<std::size_t>(e) - 1];
  };
  const DaemonConfig::Lidar& l = config_.lidar;

  // LiDAR: nothing at all, or only from other senders.
  const std::uint64_t accepted = (s.lidar_packets + s.position_packets) - (base.lidar_packets + base.position_packets);
  const std::uint64_t foreign = delta(C::kLidarRejectedSource);
  const bool silent = live_ && judged && accepted == 0 && foreign == 0 && delta(C::kLidarOversize) == 0;
  set(kLidarSilent, silent,
      format("lidar: no datagrams for %.0f s on UDP %s:%u (data) / %u (position): sensor off or unplugged, or "
             "sending to another port or address?",
             window_s, l.bind_address.c_str(), l.data_port, l.position_port),
      format("lidar: datagrams arriving on UDP port %u", l.data_port), out);
  set(kLidarForeignOnly, live_ && accepted == 0 && foreign > 0,
      format("lidar: %llu datagrams in %.0f s on UDP port %u, none from sensor_address %s: is lidar.sensor_address "
             "the sensor's?",
             static_cast<unsigned long long>(foreign), window_s, l.data_port, l.sensor_address.c_str()),
      "lidar: datagrams from the sensor_address arriving", out);
  if (const std::uint64_t n =
          rejected(vlp16::PacketError::kUnsupportedProduct) - rejected_before(vlp16::PacketError::kUnsupportedProduct);
      n > 0) {
    const std::string reason = s.model_reason.data();
    out.push_back({HealthLine::Level::kWarning,
                   format("lidar: %llu packets rejected in the last second: %s (trajroid decodes the VLP-16 only; "
                          "lidar.rejected.unsupported_product %llu)",
                          static_cast<unsigned long long>(n), reason.empty() ? "not a VLP-16" : reason.c_str(),
                          static_cast<unsigned long long>(rejected(vlp16::PacketError::kUnsupportedProduct)))});
  }
  if (const std::uint64_t n = step(C::kLidarClockJumps); n > 0) {
    out.push_back(
        {HealthLine::Level::kWarning,
         format("lidar: the sensor's clock jumped forward %llu time(s) in the last second (a time "
                "re-sync?): not counted as lost packets (lidar.clock_jumps %llu)",
                static_cast<unsigned long long>(n), static_cast<unsigned long long>(s[C::kLidarClockJumps]))});
  }

  // The serial streams the pose source reads.
  const bool gnss_used = (config_.pose_source == PoseSource::kGnssImu || config_.pose_source == PoseSource::kGnss) &&
                         !config_.gnss.device.empty();
  const bool imu_used = config_.pose_source == PoseSource::kGnssImu && !config_.imu.device.empty();
  const auto serial = [&](bool used, const char* name, const DaemonConfig::Serial& dev, C bytes, C frames,
                          C foreign_frames, const char* protocol, const char* other, Fault silent_fault,
                          Fault no_frames_fault) {
    const bool no_bytes = live_ && used && judged && delta(bytes) == 0;
    set(silent_fault, no_bytes,
        format("%s: no bytes for %.0f s from %s: receiver off, or its output on another port?", name, window_s,
               dev.device.c_str()),
        format("%s: bytes arriving from %s", name, dev.device.c_str()), out);
    const bool garbage = used && judged && delta(bytes) > 0 && delta(frames) == 0;
    std::string why;
    if (delta(foreign_frames) > 0) {
      why =
          format("%s: %llu %s frames (and no %s frame) in %.0f s from %s: gnss.device and imu.device swapped?", name,
                 static_cast<unsigned long long>(delta(foreign_frames)), other, protocol, window_s, dev.device.c_str());
    } else {
      why = format("%s: %llu bytes in %.0f s from %s at %d baud but no %s frame: wrong baud rate?", name,
                   static_cast<unsigned long long>(delta(bytes)), window_s, dev.device.c_str(), dev.baud, protocol);
    }
    set(no_frames_fault, garbage, why, format("%s: %s frames arriving", name, protocol), out);
  };
  serial(gnss_used, "gnss", config_.gnss, C::kGnssBytes, C::kGnssFrames, C::kGnssForeignFrames, "UBX", "VN-100",
         kGnssSilent, kGnssNoFrames);
  serial(imu_used, "imu", config_.imu, C::kImuBytes, C::kImuFrames, C::kImuForeignFrames, "VN-100", "UBX", kImuSilent,
         kImuNoFrames);
  set(kGnssNoPvt, gnss_used && judged && delta(C::kGnssFrames) > 0 && delta(C::kPoseFixes) == 0,
      format("gnss: %llu UBX frames in %.0f s but no NAV-PVT: enable UBX-NAV-PVT output on this port (%s)",
             static_cast<unsigned long long>(delta(C::kGnssFrames)), window_s, config_.gnss.device.c_str()),
      "gnss: NAV-PVT arriving", out);
  set(kImuNoAttitude, imu_used && judged && delta(C::kPoseImuWithoutAttitude) > 0 && delta(C::kPoseAttitudes) == 0,
      format("imu: %llu VN-100 frames in %.0f s carry no YawPitchRoll, Quaternion or DCM: add one to the binary "
             "output (register 75)",
             static_cast<unsigned long long>(delta(C::kPoseImuWithoutAttitude)), window_s),
      "imu: attitudes arriving", out);

  // The trajectory: nothing near the robot to keep.
  const double far_m = std::max(50.0, config_.roi.look_ahead_m);
  const bool far = std::isfinite(s.trajectory_distance_m) && s.trajectory_distance_m > far_m;
  set(kTrajectoryFar, far,
      format("trajectory %d: the robot is %.0f m from it (more than %.0f m): nothing near the robot is kept; is it "
             "this site's trajectory, and global_frame.origin right?",
             s.trajectory_id, s.trajectory_distance_m, far_m),
      format("trajectory %d: the robot is back within %.0f m of it", s.trajectory_id, far_m), out);

  // The host clock against GNSS time (live: in a replay the recording's receiver is not now).
  const double offset = s.host_minus_gnss_utc_s;
  set(kClockOffset, live_ && std::isfinite(offset) && std::abs(offset) > config_.time.max_gnss_offset_s,
      format("time: the host clock is %.3f s %s GNSS UTC (more than time.max_gnss_offset_s %.3f s): is NTP/chrony "
             "running and synchronised?",
             std::abs(offset), offset > 0 ? "ahead of" : "behind", config_.time.max_gnss_offset_s),
      format("time: the host clock is within %.3f s of GNSS UTC", config_.time.max_gnss_offset_s), out);

  // The state in words.
  const double since_s = static_cast<double>(s.steady_ns - previous.steady_ns) * 1e-9;
  const auto published = s.processor.sweeps_filtered - previous.processor.sweeps_filtered;
  if (active_[kLidarSilent] || (live_ && s.lidar_packets == 0)) {
    state_ = format("waiting for LiDAR data on UDP port %u", l.data_port);
  } else if (!s.pose_valid && s.processor.sweeps > 0) {
    state_ = "no valid pose: " + std::string(pose::to_string(s.pose_status));
  } else if (published > 0 && since_s > 0.0) {
    state_ = format("publishing %.1f sweeps/s", static_cast<double>(published) / since_s);
  } else {
    state_ = "receiving LiDAR data, no sweep published in the last second";
  }
  return out;
}

}  // namespace trajroi::daemon
