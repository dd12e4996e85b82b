#pragma once

// The daemon's wiring: sources, rings, threads, LCM, signals, systemd. The logic lives in the
// libraries (SweepProcessor, the drivers, the pose library).
#include <filesystem>
#include <optional>
#include <string>

#include "trajroi/daemon/config.hpp"

namespace trajroi::daemon {

struct RunOptions {
  std::optional<std::filesystem::path> replay;  // a run folder: lidar.pcap, gnss.trjb, imu.trjb
  double rate = 0.0;                            // replay pace: 0 as fast as possible, 1 real time, N × real time
  // Replay the run again and again until stopped (soak tests): each lap's recorded times are
  // shifted to follow the previous lap's; the sensors' own clocks restart each lap.
  bool loop = false;
  std::optional<std::filesystem::path> record;  // write every raw input here (same layout)
  std::string lcm_url;                          // overrides lcm.url when set
  // Fault injection for the watchdog test: after this many seconds the processing thread
  // stops making progress (it only sleeps, until the process is stopped or killed).
  std::optional<double> stall_processing_after_s;
};

inline constexpr const char* kLidarFile = "lidar.pcap";
inline constexpr const char* kGnssFile = "gnss.trjb";
inline constexpr const char* kImuFile = "imu.trjb";

// Runs until SIGTERM / SIGINT, or the end of a replay. Returns the process exit code.
int run_daemon(const DaemonConfig& config, const RunOptions& options);

}  // namespace trajroi::daemon
