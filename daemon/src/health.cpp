#include "health.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "health_format.hpp"
#include "trajroi/pipeline/pose_words.hpp"
#include "trajroi/vlp16/model.hpp"
#include "trajroi/vlp16/packet.hpp"
#include "trajroi/vlp16/position.hpp"

namespace trajroi::daemon {

namespace {

using C = Counter;

std::uint64_t rejected(const StatusSnapshot& s, vlp16::PacketError e) {
  return s.counters[static_cast<std::size_t>(C::kLidarRejected) + static_cast<std::size_t>(e) - 1];
}

std::uint64_t rejected_total(const StatusSnapshot& s) {
  std::uint64_t n = 0;
  for (std::size_t e = 1; e < vlp16::kPacketErrorCount; ++e)
    n += s.counters[static_cast<std::size_t>(C::kLidarRejected) + e - 1];
  return n;
}

// Data packets decoded (status lidar_packets counts the rejected ones too) and position packets.
std::uint64_t accepted_packets(const StatusSnapshot& s) {
  return s.lidar_packets - rejected_total(s) + s.position_packets;
}

// The data ports the LiDARs are read on, each once: "port 2368" or "ports 2368, 2369".
std::string data_ports(const DaemonConfig& config) {
  std::vector<std::uint16_t> ports;
  for (const DaemonConfig::Lidar& l : config.all_lidars())
    if (std::find(ports.begin(), ports.end(), l.data_port) == ports.end()) ports.push_back(l.data_port);
  std::string text = ports.size() == 1 ? "port " : "ports ";
  for (std::size_t i = 0; i < ports.size(); ++i)
    text += (i == 0 ? "" : ", ") + std::to_string(ports[i]);
  return text;
}

// Where trajroid listens for LiDAR datagrams: "0.0.0.0:2368 (data) / 8308 (position)" for one
// sensor; with several, each socket pair once with the sensors read on it:
// "0.0.0.0:2368 / 8308 (front, rear), 0.0.0.0:2369 / 8309 (top)".
std::string listening(const DaemonConfig& config) {
  const std::vector<DaemonConfig::Lidar> lidars = config.all_lidars();
  if (lidars.size() == 1) {
    const DaemonConfig::Lidar& l = lidars.front();
    return sprintf_text("%s:%u (data) / %u (position)", l.bind_address.c_str(), l.data_port, l.position_port);
  }
  std::string text;
  for (std::size_t i = 0; i < lidars.size(); ++i) {
    const DaemonConfig::Lidar& l = lidars[i];
    const auto same_sockets = [&l](const DaemonConfig::Lidar& o) {
      return o.bind_address == l.bind_address && o.data_port == l.data_port && o.position_port == l.position_port;
    };
    if (std::find_if(lidars.begin(), lidars.begin() + static_cast<std::ptrdiff_t>(i), same_sockets) !=
        lidars.begin() + static_cast<std::ptrdiff_t>(i))
      continue;  // said with the first sensor on these sockets
    std::string names;
    for (const DaemonConfig::Lidar& o : lidars)
      if (same_sockets(o)) names += (names.empty() ? "" : ", ") + o.name;
    text += (text.empty() ? "" : ", ") +
            sprintf_text("%s:%u / %u (%s)", l.bind_address.c_str(), l.data_port, l.position_port, names.c_str());
  }
  return text;
}

// The senders accepted: "sensor_address 192.168.1.201", or with several LiDARs each one's:
// "the sensor_address of front 127.0.0.2, rear 127.0.0.3" (a sensor without one takes any).
std::string sensor_addresses(const DaemonConfig& config) {
  const std::vector<DaemonConfig::Lidar> lidars = config.all_lidars();
  if (lidars.size() == 1) return "sensor_address " + lidars.front().sensor_address;
  std::string text;
  for (const DaemonConfig::Lidar& l : lidars)
    if (!l.sensor_address.empty()) text += (text.empty() ? "" : ", ") + l.name + " " + l.sensor_address;
  return "the sensor_address of " + text;
}

}  // namespace

std::string sender_list(const StatusSnapshot& s) {
  std::string text;
  for (const std::uint64_t sender : s.foreign_senders) {
    if (sender == 0) continue;
    in_addr address{};
    address.s_addr = htonl(static_cast<std::uint32_t>(sender >> 16));
    char name[INET_ADDRSTRLEN] = "?";
    inet_ntop(AF_INET, &address, name, sizeof name);
    text += (text.empty() ? "" : ", ") + std::string(name) + ":" + std::to_string(sender & 0xFFFF);
  }
  if (s.foreign_from_others > 0) text += " and others";
  return text.empty() ? "senders unknown" : "from " + text;
}

HealthMonitor::HealthMonitor(const DaemonConfig& config, bool live, std::int64_t start_steady_ns)
    : config_(config), live_(live) {
  lidar_model_said_.fill(-1);
  StatusSnapshot start;  // every counter starts at zero
  start.steady_ns = start_steady_ns;
  history_.push_back(start);
  minute_start_ = start;
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
  // The oldest snapshot kept is the newest at least the window old (snapshots come once a
  // second, give or take the loop's jitter).
  while (history_.size() > 2 && s.steady_ns - history_[1].steady_ns >= kWindow_ns - kJitter_ns)
    history_.pop_front();

  lidar(s, out);
  lidar_sensors(s.silent_lidars, out);
  serial_ports(s, out);
  localization(s, out);
  minute_summary(s, out);
  rings(s, out);

  // The trajectory: nothing near the robot to keep.
  const double far_m = std::max(50.0, config_.roi.look_ahead_m);
  const bool far = std::isfinite(s.trajectory_distance_m) && s.trajectory_distance_m > far_m;
  set(kTrajectoryFar, far,
      sprintf_text(
          "trajectory %d: the robot is %.0f m from it (more than %.0f m): nothing near the robot is kept; is it "
          "this site's trajectory, and global_frame.origin right?",
          s.trajectory_id, s.trajectory_distance_m, far_m),
      sprintf_text("trajectory %d: the robot is back within %.0f m of it", s.trajectory_id, far_m), out);

  clocks(s, out);
  update_state(s, previous);
  return out;
}

std::string HealthMonitor::lidar_names(std::uint32_t mask) const {
  std::string names;
  for (std::size_t i = 0; i < config_.lidars.size(); ++i) {
    if ((mask & (1U << i)) == 0) continue;
    names += (names.empty() ? "" : ", ") + config_.lidars[i].name + " (" + lidar_where(i) + ")";
  }
  return names;
}

std::vector<HealthLine> HealthMonitor::silent_lidars(std::uint32_t silent) {
  std::vector<HealthLine> out;
  lidar_sensors(silent, out);
  return out;
}

void HealthMonitor::lidar_sensors(std::uint32_t silent, std::vector<HealthLine>& out) {
  if (silent == silent_lidars_) return;
  const std::uint32_t fell = silent & ~silent_lidars_;
  const std::uint32_t back = silent_lidars_ & ~silent;
  if (fell != 0) {
    out.push_back({HealthLine::Level::kWarning,
                   sprintf_text("lidar: %s silent: no sweep for more than %.2f s (lidar_merge.silent_s); the other "
                                "sensors' sweeps are published without it (its power, cable, address or port?)",
                                lidar_names(fell).c_str(), config_.lidar_merge.silent_s)});
  }
  if (back != 0) out.push_back({HealthLine::Level::kInfo, "lidar: " + lidar_names(back) + " sends sweeps again"});
  silent_lidars_ = silent;
}

void HealthMonitor::lidar(const StatusSnapshot& s, std::vector<HealthLine>& out) {
  const StatusSnapshot& previous = history_[history_.size() - 2];
  const StatusSnapshot& base = history_.front();
  const double window = window_s(s);
  // Nothing at all, only from other senders, or only datagrams that are not VLP-16 packets.
  const std::uint64_t accepted = accepted_packets(s) - accepted_packets(base);
  const std::uint64_t foreign = delta(s, C::kLidarRejectedSource);
  const std::uint64_t not_vlp16 = delta(s, C::kLidarNotVlp16);
  const bool silent = live_ && judged(s) && accepted == 0 && foreign == 0 && not_vlp16 == 0 &&
                      delta(s, C::kLidarOversize) == 0 && rejected_total(s) == rejected_total(base);
  // With several LiDARs these name every port and address (each silent sensor is also named
  // on its own, by the merger's silent_s).
  const std::string ports = data_ports(config_);
  const std::string key = config_.lidars.size() > 1 ? "lidars[]" : "lidar";
  set(kLidarSilent, silent,
      sprintf_text("lidar: no datagrams for %.0f s on UDP %s: sensor off or unplugged, or sending to another port or "
                   "address?",
                   window, listening(config_).c_str()),
      sprintf_text("lidar: datagrams arriving on UDP %s", ports.c_str()), out);
  set(kLidarForeignOnly, live_ && accepted == 0 && foreign > 0,
      sprintf_text("lidar: %llu datagrams in %.0f s on UDP %s, none from %s: is %s.sensor_address the sensor's?",
                   static_cast<unsigned long long>(foreign), window, ports.c_str(), sensor_addresses(config_).c_str(),
                   key.c_str()),
      "lidar: datagrams from the sensor_address arriving", out);
  set(kLidarNotVlp16Only, live_ && accepted == 0 && not_vlp16 > 0,
      sprintf_text("lidar: %llu datagrams in %.0f s on UDP %s and none a VLP-16 data packet (%u–%u bytes; a VLP-16 "
                   "sends 1206; %s): another device sends to this port (%s.data_port), or the sensor's output is not "
                   "its factory packet format",
                   static_cast<unsigned long long>(not_vlp16), window, ports.c_str(), s.foreign_min_size,
                   s.foreign_max_size, sender_list(s).c_str(), key.c_str()),
      sprintf_text("lidar: VLP-16 packets arriving on UDP %s", ports.c_str()), out);
  // Each LiDAR's model as its packets are decoded, said once (and again should it ever change);
  // the packets it rejects for their model, each second.
  const bool several = config_.lidars.size() > 1;
  for (std::size_t i = 0; i < s.lidar_count; ++i) {
    const StatusSnapshot::LidarFacts& f = s.lidar[i];
    const DaemonConfig::Lidar& lane = several ? config_.lidars[i] : config_.lidar;
    const std::string lane_key = config_.lidar_key(i);
    if (f.model >= 0 && f.model != lidar_model_said_[i]) {
      const vlp16::ModelSpec& m = vlp16::spec(static_cast<vlp16::Model>(f.model));
      out.push_back(
          {HealthLine::Level::kInfo,
           "lidar: " + lidar_prefix(i) +
               sprintf_text("%s packets (product id 0x%02X), decoded with %s (%s.model %s)",
                            std::string(m.name).c_str(), static_cast<unsigned>(m.product_id),
                            lane.calibration.empty() ? "its manual's geometry"
                                                     : (lane_key + ".calibration " + lane.calibration.string()).c_str(),
                            lane_key.c_str(), lane.model.c_str())});
      lidar_model_said_[i] = f.model;
    }
    if (const std::uint64_t n = f.unsupported - previous.lidar[i].unsupported; n > 0) {
      const std::string reason = f.model_reason.data();
      out.push_back(
          {HealthLine::Level::kWarning,
           "lidar: " + lidar_prefix(i) +
               sprintf_text("%llu packets rejected in the last second: %s (trajroid decodes the VLP-16, Puck LITE, "
                            "Puck Hi-Res, VLP-32C and HDL-32E; lidar.rejected.unsupported_product %llu)",
                            static_cast<unsigned long long>(n),
                            reason.empty() ? "not a model trajroid decodes" : reason.c_str(),
                            static_cast<unsigned long long>(rejected(s, vlp16::PacketError::kUnsupportedProduct)))});
    }
  }
  if (const std::uint64_t n = s[C::kLidarClockJumps] - previous[C::kLidarClockJumps]; n > 0) {
    out.push_back(
        {HealthLine::Level::kWarning,
         sprintf_text("lidar: the sensor's clock jumped forward %llu time(s) in the last second (a time "
                      "re-sync?): not counted as lost packets (lidar.clock_jumps %llu)",
                      static_cast<unsigned long long>(n), static_cast<unsigned long long>(s[C::kLidarClockJumps]))});
  }
}

void HealthMonitor::minute_summary(const StatusSnapshot& s, std::vector<HealthLine>& out) {
  constexpr std::int64_t kMinute_ns = 60'000'000'000;
  if (s.steady_ns - minute_start_.steady_ns < kMinute_ns && !s.final) return;
  const std::uint64_t other = s[C::kLidarNotVlp16] - minute_start_[C::kLidarNotVlp16];
  const std::uint64_t packets =
      (s.lidar_packets - rejected_total(s)) - (minute_start_.lidar_packets - rejected_total(minute_start_));
  if (live_ && other > 0 && packets > 0) {
    out.push_back(
        {HealthLine::Level::kWarning,
         sprintf_text("lidar: %llu datagrams in the last %.0f s on UDP %s were not VLP-16 data packets, "
                      "beside %llu packets (%u–%u bytes; %s): another device sends to the sensor's port "
                      "(lidar.not_vlp16_datagrams %llu)",
                      static_cast<unsigned long long>(other),
                      static_cast<double>(s.steady_ns - minute_start_.steady_ns) * 1e-9, data_ports(config_).c_str(),
                      static_cast<unsigned long long>(packets), s.foreign_min_size, s.foreign_max_size,
                      sender_list(s).c_str(), static_cast<unsigned long long>(s[C::kLidarNotVlp16]))});
  }
  minute_start_ = s;
}

std::string HealthMonitor::rejecting_lidars(const StatusSnapshot& s, const StatusSnapshot& base) const {
  // Each LiDAR whose packets all came rejected for their model over the window.
  std::string text;
  for (std::size_t i = 0; i < s.lidar_count; ++i) {
    const StatusSnapshot::LidarFacts& f = s.lidar[i];
    if (f.accepted != base.lidar[i].accepted || f.unsupported <= base.lidar[i].unsupported) continue;
    const std::string reason = f.model_reason.data();
    text += (text.empty() ? "" : "; ") + (config_.lidars.size() > 1 ? "LiDAR " + lidar_prefix(i) : "LiDAR: ") +
            "packets rejected: " + (reason.empty() ? std::string("not a VLP-16") : reason);
  }
  return text;
}

void HealthMonitor::update_state(const StatusSnapshot& s, const StatusSnapshot& previous) {
  const std::string ports = data_ports(config_);
  std::string problems;
  const auto add = [&problems](const std::string& p) { problems += (problems.empty() ? "" : "; ") + p; };
  if (active_[kLidarNotVlp16Only]) {
    add(sprintf_text("LiDAR: no VLP-16 packets on UDP %s, only other datagrams", ports.c_str()));
  } else if (active_[kLidarForeignOnly]) {
    add(sprintf_text("LiDAR: datagrams on UDP %s only from addresses other than %s", ports.c_str(),
                     sensor_addresses(config_).c_str()));
  } else if (const std::string rejecting = rejecting_lidars(s, history_.front()); live_ && !rejecting.empty()) {
    add(rejecting);
  } else if (active_[kLidarSilent] || (live_ && accepted_packets(s) == 0)) {
    add("waiting for LiDAR data on UDP " + ports);
  }
  if (s.silent_lidars != 0) add("LiDAR " + lidar_names(s.silent_lidars) + ": silent, not merged");
  bool pose_input_fault = false;
  for (const std::string& serial : serial_state_) {
    if (!serial.empty()) add(serial), pose_input_fault = true;
  }
  if (active_[kLocalizationSilent] || active_[kLocalizationInvalid] || active_[kLocalizationMalformed]) {
    pose_input_fault = true;
    add(active_[kLocalizationSilent] ? "localization: no pose_input_t on " + config_.lcm.pose_input
        : active_[kLocalizationInvalid]
            ? std::string("localization: its poses are marked invalid")
            : "localization: messages on " + config_.lcm.pose_input + " are not pose_input_t");
  }
  // The pose's own reason when no input explains it.
  if (!s.pose_valid && !pose_input_fault)
    add("no valid pose: " + pipeline::pose_reason(s.pose_status, s.pose_measured, s.pose_limit, config_));
  const double since_s = static_cast<double>(s.steady_ns - previous.steady_ns) * 1e-9;
  const auto published = s.processor.sweeps_filtered - previous.processor.sweeps_filtered;
  const auto per_s = [since_s](std::uint64_t count) { return static_cast<double>(count) / since_s; };
  if (!problems.empty()) {
    state_ = problems;
  } else if (published > 0 && since_s > 0.0) {
    // Merged, the rate a subscriber sees is the merged sweeps' (the points_t messages), not the
    // sensors' sweeps in them.
    state_ = config_.merges_sweeps()
                 ? sprintf_text("publishing %.1f merged sweeps/s of %zu LiDARs (%.1f sensor sweeps/s)",
                                per_s(s[Counter::kMergePublished] - previous[Counter::kMergePublished]),
                                config_.lidars.size(), per_s(published))
             : config_.lidars.size() > 1 ? sprintf_text("publishing %.1f sweeps/s of %zu LiDARs (each alone)",
                                                        per_s(published), config_.lidars.size())
                                         : sprintf_text("publishing %.1f sweeps/s", per_s(published));
  } else {
    state_ = "receiving LiDAR data, no sweep published in the last second";
  }
}

}  // namespace trajroi::daemon
