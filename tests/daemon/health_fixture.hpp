#pragma once

// The health tests' fixture: a live configuration, snapshots made one a second by a test's
// change and fed to a HealthMonitor, and what it said (health_test.cpp, health_lidars_test.cpp).
#include <limits>
#include <string>
#include <vector>

#include "health.hpp"
#include "trajroi/vlp16/packet.hpp"

namespace trajroi::daemon::health_test {

inline constexpr std::int64_t kSecond = 1'000'000'000;

inline DaemonConfig live_config() {
  DaemonConfig c;
  c.lidar.data_port = 2368;
  c.lidar.sensor_address = "192.168.1.201";
  c.gnss.device = "/dev/gnss";
  c.imu.device = "/dev/imu";
  return c;
}

// Runs `seconds` snapshots (one a second from a start at 0), `change` making each; returns
// every line said, and the second each first came.
struct Said {
  std::vector<HealthLine> lines;
  std::vector<int> at_s;
  std::string state;
  [[nodiscard]] int first(const std::string& part) const {
    for (std::size_t i = 0; i < lines.size(); ++i)
      if (lines[i].text.find(part) != std::string::npos) return at_s[i];
    return -1;
  }
  [[nodiscard]] std::string all() const {
    std::string out;
    for (const auto& l : lines)
      out += l.text + "\n";
    return out;
  }
};

template <class Change>
Said run(const DaemonConfig& config, int seconds, Change change, bool live = true) {
  HealthMonitor monitor(config, live, 0);
  StatusSnapshot s;
  s.trajectory_distance_m = std::numeric_limits<double>::quiet_NaN();
  s.host_minus_gnss_utc_s = std::numeric_limits<double>::quiet_NaN();
  Said said;
  for (int t = 1; t <= seconds; ++t) {
    s.steady_ns = t * kSecond;
    change(s, t);
    for (HealthLine& l : monitor.update(s)) {
      said.lines.push_back(std::move(l));
      said.at_s.push_back(t);
    }
  }
  said.state = monitor.state();
  return said;
}

// A healthy second: a VLP-16's 754 data packets, GNSS and IMU frames, fixes and attitudes.
inline void healthy(StatusSnapshot& s, int) {
  s.lidar_packets += 754;
  s.position_packets += 1;
  s[Counter::kGnssBytes] += 1000;
  s[Counter::kGnssFrames] += 10;
  s[Counter::kPoseFixes] += 10;
  s[Counter::kImuBytes] += 5000;
  s[Counter::kImuFrames] += 40;
  s[Counter::kPoseAttitudes] += 40;
  s.processor.sweeps += 10;
  s.processor.sweeps_filtered += 10;
  s.pose_valid = true;
  s.pose_status = trajroi::pose::PoseStatus::kValid;
}

// `n` data packets of LiDAR `lidar` received and rejected for their model, the model check
// saying `reason`: counted in the status counters and in that LiDAR's own.
inline void reject_for_model(StatusSnapshot& s, std::size_t lidar, std::uint64_t n, const std::string& reason) {
  s.lidar_packets += n;
  s.counters[static_cast<std::size_t>(Counter::kLidarRejected) +
             static_cast<std::size_t>(trajroi::vlp16::PacketError::kUnsupportedProduct) - 1] += n;
  s.lidar[lidar].unsupported += n;
  s.lidar[lidar].model_reason.fill('\0');
  reason.copy(s.lidar[lidar].model_reason.data(), s.lidar[lidar].model_reason.size() - 1);
}

// lidars: front and rear (192.168.1.202) on the live configuration's ports.
inline DaemonConfig two_lidars() {
  DaemonConfig c = live_config();
  DaemonConfig::Lidar rear = c.lidar;
  rear.name = "rear";
  rear.sensor_address = "192.168.1.202";
  c.lidar.name = "front";
  c.lidars = {c.lidar, rear};
  return c;
}

}  // namespace trajroi::daemon::health_test
