// trajroid — the trajectory-ROI daemon. See docs/daemon.md and docs/configuration.md.
#include <malloc.h>
#include <spawn.h>
#include <sys/wait.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "log.hpp"
#include "reload.hpp"
#include "trajroi/daemon/trajectory_file.hpp"
#include "trajroi/daemon/unit_allow.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroid.hpp"

namespace {

// Said before the logger exists: the journal files these lines as errors.
const char* error_prefix() {
  return trajroi::daemon::log::journal_prefix(spdlog::level::err);
}

// `trajroid --apply-to-unit UNIT`: the unit's allow-lists for this configuration, set on the
// starting unit by systemctl (run as the unit's privileged ExecStartPre).
int apply_to_unit(const trajroi::daemon::UnitAllowLists& lists, const std::string& unit) {
  for (const std::string& reason : lists.reasons)
    std::printf("%s: allowing %s\n", unit.c_str(), reason.c_str());
  for (const std::string& problem : lists.problems)
    std::fprintf(stderr, "%s%s: %s\n", trajroi::daemon::log::journal_prefix(spdlog::level::warn), unit.c_str(),
                 problem.c_str());
  std::fflush(stdout);
  const std::vector<std::string> args = trajroi::daemon::set_property_arguments(lists, unit);
  std::vector<char*> argv;
  for (const std::string& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t child = 0;
  if (const int e = posix_spawnp(&child, argv[0], nullptr, nullptr, argv.data(), environ); e != 0) {
    std::fprintf(stderr, "%strajroid: --apply-to-unit: cannot run systemctl: %s\n", error_prefix(), std::strerror(e));
    return 1;
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr,
                 "%strajroid: --apply-to-unit %s: systemctl set-property failed (status %d): the unit keeps "
                 "its own allow-lists\n",
                 error_prefix(), unit.c_str(), WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace trajroi::daemon;
  // The daemon allocates its buffers at start and keeps them. glibc would give each large one a
  // mapping of its own (and give a heap's free top back), so that freeing them at exit unmaps
  // each in turn, each time with a TLB shootdown to the other cores: an interrupt per core, which
  // in a virtual machine is an exit to the hypervisor (on an AMD EPYC guest, Zen 5, 4 of the
  // 10 ms an as-fast replay's exit took). From the heap, and kept, they go with the process.
  (void)mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest
  (void)mallopt(M_TRIM_THRESHOLD, 1 << 30);
  CLI::App app{"trajroid: VLP-16 + u-blox + VN-100 in, trajectory-ROI-filtered points out over LCM"};
  app.set_version_flag("--version", std::string("trajroid ") + TRAJROI_VERSION);
  std::string config_file;
  std::string replay, record, rate = "max", lcm_url;
  std::string apply_unit;
  bool check_config = false, loop = false, print_drop_in = false, print_reference = false;
  app.add_option("--config", config_file, "YAML configuration (see config/trajroid.yaml)");
  app.add_flag("--config-reference", print_reference,
               "Print every configuration key with its type, default and meaning (Markdown), and exit");
  app.add_option("--replay", replay, "Replay a run folder (lidar.pcap, gnss.trjb, imu.trjb) instead of the sensors");
  app.add_option("--rate", rate, "Replay pace: realtime, max, or a factor of real time (e.g. 10)")
      ->capture_default_str();
  app.add_flag("--loop", loop, "With --replay: play the run again and again (times shifted each lap) until stopped");
  app.add_option("--record", record, "Record every raw input with its host receive time into this folder");
  app.add_option("--lcm-url", lcm_url, "LCM provider URL (overrides lcm.url)");
  app.add_flag("--check-config", check_config, "Check the configuration, print a summary and exit");
  app.add_flag("--unit-drop-in", print_drop_in,
               "Print the systemd drop-in (IPAddressAllow=, DeviceAllow=) this configuration needs, and exit");
  app.add_option("--apply-to-unit", apply_unit,
                 "Set those allow-lists on UNIT for this boot (systemctl set-property --runtime), and exit: the "
                 "unit's privileged ExecStartPre");
  double stall_after_s = -1.0;
  app.add_option("--inject-processing-stall", stall_after_s,
                 "Testing only: the processing thread stops making progress after SECONDS (watchdog test)")
      ->group("Testing");
  try {
    app.parse(argc, argv);
    if (print_reference) {
      std::printf("%s", config_reference().c_str());
      return 0;
    }
    if (config_file.empty()) throw CLI::RequiredError("--config");
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  DaemonConfig config;
  try {
    config = load_daemon_config(config_file);
  } catch (const trajroi::config::ConfigError& e) {
    if (!apply_unit.empty()) {
      // The unit's ExecStartPre: the daemon that follows names the error and exits 78 (not
      // restarted); failing here would have systemd restart the unit in a loop.
      std::printf("%s: configuration error, its allow-lists are left as they are\n", apply_unit.c_str());
      return 0;
    }
    std::fprintf(stderr, "%strajroid: configuration error: %s\n", error_prefix(), e.what());
    return kExitConfig;
  }
  RunOptions options;
  if (!replay.empty()) options.replay = replay;
  if (!record.empty()) options.record = record;
  if (loop && replay.empty()) {
    std::fprintf(stderr, "%strajroid: --loop needs --replay\n", error_prefix());
    return kExitConfig;
  }
  options.loop = loop;
  if (const std::string problem = check_lcm_url(lcm_url); !lcm_url.empty() && !problem.empty()) {
    std::fprintf(stderr, "%strajroid: --lcm-url '%s': %s\n", error_prefix(), lcm_url.c_str(), problem.c_str());
    return kExitConfig;
  }
  if (print_drop_in || !apply_unit.empty()) {
    const UnitAllowLists lists =
        unit_allow_lists(config, lcm_url.empty() ? config.lcm.url : lcm_url, host_ipv4_addresses());
    if (print_drop_in) std::printf("%s", unit_drop_in(lists, config_file).c_str());
    return apply_unit.empty() ? 0 : apply_to_unit(lists, apply_unit);
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
      std::fprintf(stderr, "%strajroid: --rate: expected realtime, max or a factor > 0, got '%s'\n", error_prefix(),
                   rate.c_str());
      return kExitConfig;
    }
  }
  // The trajectory file is part of the configuration: read once, here.
  std::unique_ptr<trajroi::pipeline::ActiveTrajectory> trajectory;
  try {
    trajectory = load_trajectory(TrajectorySource::from(config));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%strajroid: configuration error: %s: trajectory.file: %s: %s\n", error_prefix(),
                 config_file.c_str(), config.trajectory_file.c_str(), e.what());
    return kExitConfig;
  }
  if (check_config) {
    // So are the LiDARs' calibration files (a start reads them as it builds the pipeline, with
    // the same errors): a malformed one, or one of another model's laser count.
    const std::vector<DaemonConfig::Lidar> lidars = config.all_lidars();
    for (std::size_t i = 0; i < lidars.size(); ++i) {
      try {
        (void)trajroi::pipeline::load_calibration(lidars[i], config.lidar_key(i));
      } catch (const std::exception& e) {
        std::fprintf(stderr, "%strajroid: configuration error: %s: %s\n", error_prefix(), config_file.c_str(),
                     e.what());
        return kExitConfig;
      }
    }
    std::printf("%s", describe(config).c_str());
    // The devices the pose source reads that are not there now: not an error (a USB receiver
    // may come later), but said, with what the daemon will do.
    const bool gnss = config.pose_source == PoseSource::kGnssImu || config.pose_source == PoseSource::kGnss;
    const bool imu = config.pose_source == PoseSource::kGnssImu;
    for (const auto& [used, key, device] :
         {std::tuple{gnss, "gnss.device", config.gnss.device}, std::tuple{imu, "imu.device", config.imu.device}}) {
      std::error_code ec;
      if (used && !device.empty() && !std::filesystem::exists(device, ec)) {
        std::printf(
            "%s: %s %s does not exist now: trajroid will start and wait for it (retried every 0.5 s; "
            "its log and status say so until it appears)\n",
            config_file.c_str(), key, device.c_str());
      }
    }
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
