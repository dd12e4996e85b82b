// The time's health: the host clock against GNSS UTC and each LiDAR's PPS-locked UTC, and each
// LiDAR's PPS lost after it had locked. Live only: in a replay the recording's receiver and
// sensors are not now.
#include <cmath>

#include "health.hpp"
#include "health_format.hpp"
#include "trajroi/vlp16/model.hpp"
#include "trajroi/vlp16/position.hpp"

namespace trajroi::daemon {

std::string HealthMonitor::lidar_where(std::size_t lane) const {
  const DaemonConfig::Lidar& l = config_.lidars[lane];
  return (l.sensor_address.empty() ? std::string("any sender") : l.sensor_address) + " → UDP " +
         std::to_string(l.data_port);
}

std::string HealthMonitor::lidar_prefix(std::size_t lane) const {
  return config_.lidars.size() > 1 ? lidar_names(1U << lane) + ": " : std::string();
}

std::string HealthMonitor::lidar_possessive(const StatusSnapshot& s, std::size_t lane) const {
  if (config_.lidars.size() > 1) return "the " + config_.lidars[lane].name + " LiDAR's (" + lidar_where(lane) + ")";
  const std::int8_t model = s.lidar[lane].model;
  return "the " + (model >= 0 ? std::string(vlp16::spec(static_cast<vlp16::Model>(model)).name) : "LiDAR") + "'s";
}

void HealthMonitor::clocks(const StatusSnapshot& s, std::vector<HealthLine>& out) {
  const double gnss = s.host_minus_gnss_utc_s;
  const double limit = config_.time.max_gnss_offset_s;
  set(kClockOffset, live_ && std::isfinite(gnss) && std::abs(gnss) > limit,
      sprintf_text("time: the host clock is %.3f s %s GNSS UTC (NAV-PVT, time accuracy %.3g s; more than "
                   "time.max_gnss_offset_s %.3f s): is NTP/chrony running and synchronised?",
                   std::abs(gnss), gnss > 0 ? "ahead of" : "behind", s.gnss_time_accuracy_s, limit),
      sprintf_text("time: the host clock is within %.3f s of GNSS UTC", limit), out);
  // Each LiDAR's clock and PPS, the sensors at fault named in one line.
  const double lidar_limit = config_.time.max_lidar_offset_s;
  std::string off, lost;
  for (std::size_t i = 0; i < s.lidar_count; ++i) {
    const StatusSnapshot::LidarFacts& f = s.lidar[i];
    const double d = f.host_minus_utc_s;
    if (live_ && std::isfinite(d) && std::abs(d) > lidar_limit) {
      off += (off.empty() ? "" : ", and ") + sprintf_text("%.3f s %s ", std::abs(d), d > 0 ? "ahead of" : "behind") +
             lidar_possessive(s, i) + " PPS-locked UTC";
    }
    // Its PPS, once locked, lost: its stamps run on its own clock until it locks again.
    const auto pps = static_cast<vlp16::PpsStatus>(static_cast<std::uint8_t>(f.pps_status));
    if (f.pps_status >= 0 && pps == vlp16::PpsStatus::kLocked) lidar_pps_locked_once_[i] = true;
    if (live_ && lidar_pps_locked_once_[i] && f.pps_status >= 0 && pps != vlp16::PpsStatus::kLocked)
      lost += (lost.empty() ? "" : "; ") + lidar_possessive(s, i) + " PPS is " + std::string(vlp16::to_string(pps));
  }
  const bool several = config_.lidars.size() > 1;
  set(kLidarClockOffset, !off.empty(),
      "time: the host clock is " + off +
          sprintf_text(" (more than time.max_lidar_offset_s %.3f s): is the host clock synchronised (chrony), and "
                       "the sensor's GPS time right?",
                       lidar_limit),
      sprintf_text("time: the host clock is within %.3f s of %s UTC", lidar_limit,
                   several ? "every LiDAR's" : lidar_possessive(s, 0).c_str()),
      out);
  set(kLidarPpsLost, !lost.empty(),
      "lidar: " + lost +
          " after it had locked: its time stamps follow its own clock until it locks again (GPS receiver, antenna or "
          "PPS wire?)",
      several ? std::string("lidar: every LiDAR's PPS is locked again")
              : "lidar: " + lidar_possessive(s, 0) + " PPS is locked again",
      out);
}

}  // namespace trajroi::daemon
