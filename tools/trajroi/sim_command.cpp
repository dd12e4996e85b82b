// trajroi sim: a scenario file → a run folder of sensor streams and ground truth.
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "file_io.hpp"
#include "trajroi/sim/run_folder.hpp"
#include "trajroi/sim/scenario.hpp"

namespace trajroi::cli {
namespace {

struct SimOptions {
  std::string scenario;
  std::string out;
  bool quiet = false;
};

void run_sim(const SimOptions& options) {
  const std::string text = read_text_file(options.scenario);
  const sim::Scenario scenario = sim::parse_scenario(text, options.scenario);  // nothing written if bad
  std::fprintf(stderr, "trajroi sim: scenario '%s' → %s\n", scenario.name.c_str(), options.out.c_str());
  const bool show = !options.quiet && isatty(STDERR_FILENO) != 0;  // a progress line, for people only
  const sim::RunReport report = sim::write_run(scenario, text, options.out, [&](double fraction) {
    if (show) std::fprintf(stderr, "\r  lidar %5.1f %%", 100.0 * fraction);
  });
  if (show) std::fprintf(stderr, "\r  lidar 100.0 %%\n");
  const sim::SimulationStats& s = report.stats;
  std::printf("scenario %s: %.1f s of driving in %.1f s (%.1fx real time)\n", scenario.name.c_str(),
              static_cast<double>(s.duration_ns) * 1e-9, report.wall_s, report.realtime_factor());
  std::printf("  lidar.pcap  %llu data packets, %llu position packets, %llu points (%llu in the truth corridor)\n",
              static_cast<unsigned long long>(s.data_packets), static_cast<unsigned long long>(s.position_packets),
              static_cast<unsigned long long>(s.points), static_cast<unsigned long long>(s.points_in_corridor));
  std::printf("  gnss.trjb   %llu epochs (NAV-HPPOSLLH + NAV-PVT)\n", static_cast<unsigned long long>(s.gnss_epochs));
  std::printf("  imu.trjb    %llu VN-100 frames\n", static_cast<unsigned long long>(s.imu_frames));
}

}  // namespace

void add_sim_command(CLI::App& app) {
  auto options = std::make_shared<SimOptions>();
  CLI::App* cmd = app.add_subcommand("sim", "Simulate a scenario: VLP-16 pcap, GNSS and IMU recordings, ground truth");
  cmd->add_option("--scenario", options->scenario, "Scenario YAML (see config/scenarios/factory.yaml)")->required();
  cmd->add_option("--out", options->out, "Run folder to write (replaced if it exists)")->required();
  cmd->add_flag("--quiet", options->quiet, "No progress on stderr");
  cmd->callback([options] { run_sim(*options); });
}

}  // namespace trajroi::cli
