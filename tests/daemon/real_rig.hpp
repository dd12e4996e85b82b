#pragma once

// The live rig of the tests on real captures (real_captures_test.cpp, live_messages_test.cpp):
// a configuration for one pose source pointed at its own UDP ports, device links and LCM
// channels; `trajroi feed` arguments that play a capture into it; and the wait for a log line.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "daemon_fixture.hpp"
#include "trajroi/pose/geodetic.hpp"

namespace daemon_test {

using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr const char* kPcap = "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap";
constexpr const char* kUbx = "ublox/gpsd/ublox-neo-m8p.log";
constexpr const char* kVn100 = "vectornav/LoggerWavesInIce_F00379.raw";

// The global frame's origin, a few metres from the receiver's fix (50.1350851 N, 14.4299466 E,
// 348.86 m), and a north-south trajectory 0.24 m east of the fix, as latitude/longitude. The
// capture's returns all lie within 2.8 m of the sensor (a small room): 1.2 m circles over 6 m
// ahead keep a part of each sweep.
const trajroi::pose::Geodetic kOrigin{50.13505, 14.42990, 348.0};
constexpr const char* kTrajectoryLatLon = "lat,lon\n50.13480,14.42995\n50.13540,14.42995\n";

struct Rig {
  std::string prefix;
  fs::path dir, config, gnss_link, imu_link, daemon_log, feed_log, trajectory_xy;
  int data_port = 0;

  // `lidar_extra`: more lidar keys ("  sensor_address: …\n"); `fixed`: pose.fixed for source fixed.
  Rig(const std::string& name, const std::string& source, int port_offset, const std::string& lidar_extra = "",
      const std::string& fixed = "{xyz: [3.3, 2.0, 0.5], yaw_deg: 60}") {
    const int pid = ::getpid();
    prefix = "TRJREAL_" + std::to_string(pid) + "_" + name;
    dir = fs::temp_directory_path() / ("trajroid_real_" + name + "_" + std::to_string(pid));
    fs::create_directories(dir);
    data_port = 24000 + (pid % 1000) * 40 + port_offset * 2;  // offsets 0 … 19
    gnss_link = dir / "gnss";
    imu_link = dir / "imu";
    daemon_log = dir / "trajroid.log";
    feed_log = dir / "feed.log";
    std::ofstream(dir / "trajectory.csv") << kTrajectoryLatLon;
    // The same trajectory in global-frame metres, for trajroi filter.
    const auto frame = trajroi::pose::GlobalFrame::local_cartesian(kOrigin);
    trajectory_xy = dir / "trajectory_xy.csv";
    std::ofstream xy(trajectory_xy);
    xy.precision(17);
    for (const double lat : {50.13480, 50.13540}) {
      const Eigen::Vector3d g = frame.to_global(trajroi::pose::Geodetic{lat, 14.42995, kOrigin.height_m});
      xy << g.x() << "," << g.y() << "\n";
    }
    char origin[160];
    std::snprintf(origin, sizeof origin, "{lat_deg: %.8f, lon_deg: %.8f, height_m: %.3f}", kOrigin.lat_deg,
                  kOrigin.lon_deg, kOrigin.height_m);
    std::string text = std::string("global_frame:\n  origin: ") + origin +
                       "\ntrajectory:\n  file: trajectory.csv\n"
                       "lidar:\n  data_port: " +
                       std::to_string(data_port) + "\n  position_port: " + std::to_string(data_port + 1) +
                       "\n  min_range_m: 0.5\n  max_range_m: 60\n" + lidar_extra;
    if (source == "gnss_imu" || source == "gnss") text += "gnss:\n  device: " + gnss_link.string() + "\n";
    if (source == "gnss_imu") text += "imu:\n  device: " + imu_link.string() + "\n";
    text += "pose:\n  source: " + source + "\n  mode: per_sweep\n";
    // Parked receiver: no course over ground; the robot faces north-east until it moves.
    if (source == "gnss") text += "  gnss_heading: {initial_heading_deg: 30}\n";
    if (source == "fixed") text += "  fixed: " + fixed + "\n";
    text += "roi:\n  circle_diameter_m: 1.2\n  look_ahead_m: 6\n";
    text += "lcm:\n  channels: {points: " + prefix + "_POINTS, pose: " + prefix + "_POSE, roi: " + prefix +
            "_ROI, status: " + prefix + "_STATUS, trajectory: " + prefix + "_TRAJECTORY, pose_input: " + prefix +
            "_POSE_INPUT}\n";
    config = dir / "trajroid.yaml";
    std::ofstream(config) << text;
  }
  ~Rig() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  // Adds `lines` ("  max_h_acc_m: 0.01\n") under the top-level `section` ("pose").
  void add_under(const std::string& section, const std::string& lines) const {
    std::string text = slurp(config);
    const std::string head = "\n" + section + ":\n";
    const auto at = text.find(head);
    if (at == std::string::npos) {
      text += section + ":\n" + lines;
    } else {
      text.insert(at + head.size(), lines);
    }
    std::ofstream(config) << text;
  }
  [[nodiscard]] std::vector<std::string> daemon_args() const {
    return {"--config", config.string(), "--lcm-url", kTestLcmUrl};
  }
  // `trajroi feed` playing `pcap` to this rig's ports, its first datagram `lidar_after` s in.
  [[nodiscard]] std::vector<std::string> pcap_feed(const fs::path& pcap, const std::string& lidar_after,
                                                   std::vector<std::string> extra = {}) const {
    std::vector<std::string> a{"feed",
                               "--pcap",
                               pcap.string(),
                               "--data-port",
                               std::to_string(data_port),
                               "--position-port",
                               std::to_string(data_port + 1),
                               "--lidar-after",
                               lidar_after};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  // SIGTERM: the daemon must stop cleanly.
  void stop(Child& daemon) const {
    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.wait(seconds(5)), 0) << logs();
  }
  [[nodiscard]] std::string logs() const {
    return "--- config ---\n" + slurp(config) + "--- trajroid log ---\n" + slurp(daemon_log) + "--- feed log ---\n" +
           slurp(feed_log);
  }
};

// Seconds from `start` until `text` appears in the log (-1: not within `timeout`).
inline double seconds_until_logged(const fs::path& log, const std::string& text,
                                   std::chrono::steady_clock::time_point start, std::chrono::milliseconds timeout) {
  const auto until = start + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (slurp(log).find(text) != std::string::npos) {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    std::this_thread::sleep_for(milliseconds(50));
  }
  return -1.0;
}

// Whether trajroid says it runs within 5 s (its sockets bound, its scans and decoder
// calibrated: it reads from the next moment). A feed started before that sends its first
// datagrams to ports not yet bound: on a 2-core Zen 5 guest trajroid's start-up took 110 ms,
// and a 0.39 s capture lost frame 0 and part of frame 1.
inline bool wait_until_running(const fs::path& daemon_log) {
  return seconds_until_logged(daemon_log, "trajroid running", std::chrono::steady_clock::now(), milliseconds(5000)) >=
         0.0;
}

#define EXPECT_LOGGED_WITHIN_5S(rig, text, start)                                                    \
  do {                                                                                               \
    const double at_s = seconds_until_logged((rig).daemon_log, (text), (start), milliseconds(6000)); \
    EXPECT_GE(at_s, 0.0) << "not logged: " << (text) << "\n" << (rig).logs();                        \
    EXPECT_LE(at_s, 5.5) << (text);                                                                  \
  } while (0)

}  // namespace daemon_test
