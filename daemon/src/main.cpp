// trajroid — the trajectory-ROI daemon. See daemon/README.md and config/trajroid.yaml.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>

#include "log.hpp"
#include "reload.hpp"
#include "trajroi/daemon/trajectory_file.hpp"
#include "trajroid.hpp"

int main(int argc, char** argv) {
  using namespace trajroi::daemon;
  CLI::App app{"trajroid: VLP-16 + u-blox + VN-100 in, trajectory-ROI-filtered points out over LCM"};
  app.set_version_flag("--version", std::string("trajroid ") + TRAJROI_VERSION);
  std::string config_file;
  std::string replay, record, rate = "max", lcm_url;
  bool check_config = false, loop = false;
  app.add_option("--config", config_file, "YAML configuration (see config/trajroid.yaml)")->required();
  app.add_option("--replay", replay, "Replay a run folder (lidar.pcap, gnss.trjb, imu.trjb) instead of the sensors");
  app.add_option("--rate", rate, "Replay pace: realtime, max, or a factor of real time (e.g. 10)")
      ->capture_default_str();
  app.add_flag("--loop", loop, "With --replay: play the run again and again (times shifted each lap) until stopped");
  app.add_option("--record", record, "Record every raw input with its host receive time into this folder");
  app.add_option("--lcm-url", lcm_url, "LCM provider URL (overrides lcm.url)");
  app.add_flag("--check-config", check_config, "Check the configuration, print a summary and exit");
  double stall_after_s = -1.0;
  app.add_option("--inject-processing-stall", stall_after_s,
                 "Testing only: the processing thread stops making progress after SECONDS (watchdog test)")
      ->group("Testing");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  DaemonConfig config;
  try {
    config = load_daemon_config(config_file);
  } catch (const trajroi::config::ConfigError& e) {
    std::fprintf(stderr, "trajroid: configuration error: %s\n", e.what());
    return kExitConfig;
  }
  RunOptions options;
  if (!replay.empty()) options.replay = replay;
  if (!record.empty()) options.record = record;
  if (loop && replay.empty()) {
    std::fprintf(stderr, "trajroid: --loop needs --replay\n");
    return kExitConfig;
  }
  options.loop = loop;
  if (const std::string problem = check_lcm_url(lcm_url); !lcm_url.empty() && !problem.empty()) {
    std::fprintf(stderr, "trajroid: --lcm-url '%s': %s\n", lcm_url.c_str(), problem.c_str());
    return kExitConfig;
  }
  options.lcm_url = lcm_url;
  if (stall_after_s >= 0.0) options.stall_processing_after_s = stall_after_s;
  if (rate == "max") {
    options.rate = 0.0;
  } else if (rate == "realtime") {
    options.rate = 1.0;
  } else {
    try {
      std::size_t used = 0;
      options.rate = std::stod(rate, &used);
      if (used != rate.size() || !(options.rate > 0.0) || options.rate > 1e6) throw std::invalid_argument(rate);
    } catch (const std::exception&) {
      std::fprintf(stderr, "trajroid: --rate: expected realtime, max or a factor > 0, got '%s'\n", rate.c_str());
      return kExitConfig;
    }
  }
  // The trajectory file is part of the configuration: read once, here.
  std::unique_ptr<ActiveTrajectory> trajectory;
  try {
    trajectory = load_trajectory(TrajectorySource::from(config));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trajroid: configuration error: %s: trajectory.file: %s: %s\n", config_file.c_str(),
                 config.trajectory_file.c_str(), e.what());
    return kExitConfig;
  }
  if (check_config) {
    std::printf("%s", describe(config).c_str());
    std::printf("%s: configuration OK (trajectory %s: %zu waypoints, %.1f m; pose from %s; LCM %s)\n",
                config_file.c_str(), config.trajectory_file.c_str(), trajectory->trajectory.waypoints().size(),
                trajectory->trajectory.length_m(), std::string(to_string(config.pose_source)).c_str(),
                (lcm_url.empty() ? config.lcm.url : lcm_url).c_str());
    return 0;
  }
  log::init(config.logging.level);
  try {
    return run_daemon(config, std::move(trajectory), options);
  } catch (const std::exception& e) {
    log::critical("fatal: {}", e.what());
    return 1;
  }
}
