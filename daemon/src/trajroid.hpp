#pragma once

// The daemon's wiring: the sources, the pipeline's rings and threads, signals, systemd notify
// and watchdog. Each thread's loop lives in a file of its own (threads.hpp, publisher.hpp).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "trajroi/daemon/config.hpp"

namespace trajroi::pipeline {
class SweepProcessor;
struct ActiveTrajectory;
}  // namespace trajroi::pipeline

namespace trajroi::daemon {

struct Pipeline;
class Outlet;

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

// Runs until SIGTERM / SIGINT, or the end of a replay. Returns the process exit code.
int run_daemon(const DaemonConfig& config, std::unique_ptr<pipeline::ActiveTrajectory> trajectory,
               const RunOptions& options);

// The pipeline's threads over the inputs already added to `pipeline`, until the inputs end or
// `pipeline.stop` is set (by SIGTERM / SIGINT when `signals`; SIGHUP then reloads the
// trajectory). Logs the summary; returns the exit code. What run_daemon and the tests call.
int run_pipeline(Pipeline& pipeline, pipeline::SweepProcessor& processor, Outlet& outlet, const RunOptions& options,
                 bool signals);

}  // namespace trajroi::daemon
