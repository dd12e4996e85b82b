// trajroid's configuration: the documented example reads, and every kind of mistake stops the
// daemon with exit code 78 and a message naming the file, line, key and value.
#include "trajroi/daemon/config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "daemon_fixture.hpp"

namespace {

using namespace trajroi::daemon;
namespace fs = std::filesystem;

std::string example() {
  return daemon_test::slurp(TRAJROI_EXAMPLE_CONFIG);
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string error_of(const std::string& text) {
  try {
    (void)parse_daemon_config(text, fs::path(TRAJROI_EXAMPLE_CONFIG));
  } catch (const trajroi::config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(DaemonConfig, TheDocumentedExampleReadsWithItsValues) {
  const DaemonConfig c = parse_daemon_config(example(), fs::path(TRAJROI_EXAMPLE_CONFIG));
  EXPECT_DOUBLE_EQ(c.origin.lat_deg, 36.3721);
  EXPECT_EQ(c.trajectory_file, fs::path(TRAJROI_EXAMPLE_CONFIG).parent_path() / "trajectory.csv");
  EXPECT_EQ(c.lidar.data_port, 2368);
  EXPECT_DOUBLE_EQ(c.lidar.robot_from_lidar.translation().z(), 0.7);
  EXPECT_EQ(c.pose_mode, PoseMode::kPerFiring);
  EXPECT_EQ(c.gate.max_extrapolation_ns, 250'000'000);
  EXPECT_EQ(c.roi.shape, RoiShape::kCircular);
  EXPECT_DOUBLE_EQ(c.roi.spacing_ratio, 0.25);
  EXPECT_EQ(c.lcm.url, "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(c.lcm.trajectory, "TRAJROI_TRAJECTORY");
  EXPECT_EQ(c.buffers.max_points_per_sweep, 131072u);
  EXPECT_EQ(c.realtime.processing.policy, SchedPolicy::kOther);
}

TEST(DaemonConfig, MistakesAreNamedByFileLineKeyAndValue) {
  const std::string file = TRAJROI_EXAMPLE_CONFIG;
  EXPECT_NE(error_of(replaced(example(), "  shape: circular", "  shape: hexagon")).find("roi.shape"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(example(), "  shape: circular", "  shape: hexagon")).find("hexagon"), std::string::npos);
  const std::string unknown = error_of(replaced(example(), "  data_port: 2368", "  data_prot: 2368"));
  EXPECT_NE(unknown.find("lidar.data_prot"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find(file + ":"), std::string::npos) << unknown;
  EXPECT_NE(error_of(replaced(example(), "  data_port: 2368", "  data_port: 70000"))
                .find("lidar.data_port: must be a UDP port"),
            std::string::npos);
  EXPECT_NE(
      error_of(replaced(example(), "  max_h_acc_m: 0.5", "  max_h_acc_m: -1")).find("pose.max_h_acc_m: must be > 0"),
      std::string::npos);
  EXPECT_NE(error_of(replaced(example(), "    lidar: {policy: other}", "    lidar: {policy: fifo, priority: 120}"))
                .find("realtime.threads.lidar.priority"),
            std::string::npos);
  EXPECT_NE(
      error_of(replaced(example(), "  spacing_ratio: 0.25", "  spacing_ratio: 0.000001")).find("roi.spacing_ratio"),
      std::string::npos);
  EXPECT_NE(error_of(replaced(example(), "global_frame:", "global_fram:")).find("global_frame"), std::string::npos);
}

struct DaemonRun {
  int code;
  std::string err;
};

DaemonRun trajroid(const fs::path& config, const std::string& extra = "") {
  // stderr goes to the temporary folder, never beside the configuration (the example's is in
  // the source tree).
  const fs::path err = fs::temp_directory_path() /
                       ("trajroid_config_" + std::to_string(::getpid()) + "_" + config.filename().string() + ".err");
  const int code = daemon_test::run_command(std::string(TRAJROID) + " --config " + config.string() + " " + extra +
                                            " >/dev/null 2>" + err.string());
  return {code, daemon_test::slurp(err)};
}

TEST(DaemonConfig, TheDaemonExitsWith78OnABadConfigurationAndCheckConfigPassesAGoodOne) {
  EXPECT_EQ(trajroid(TRAJROI_EXAMPLE_CONFIG, "--check-config").code, 0);
  const fs::path dir = fs::temp_directory_path() / ("trajroid_config_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "trajectory.csv") << "0,0\n10,0\n";
  const auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  const fs::path bad_value = write("bad_value.yaml", replaced(example(), "  level: info", "  level: loud"));
  for (const char* mode : {"--check-config", ""}) {
    const DaemonRun r = trajroid(bad_value, mode);
    EXPECT_EQ(r.code, 78) << r.err;
    EXPECT_NE(r.err.find(bad_value.string() + ":"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("logging.level"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("loud"), std::string::npos) << r.err;
  }
  const DaemonRun missing_trajectory = trajroid(
      write("no_trajectory.yaml", replaced(example(), "file: trajectory.csv", "file: nowhere.csv")), "--check-config");
  EXPECT_EQ(missing_trajectory.code, 78);
  EXPECT_NE(missing_trajectory.err.find("nowhere.csv"), std::string::npos) << missing_trajectory.err;
  std::ofstream(dir / "one_point.csv") << "1,1\n";
  const DaemonRun bad_trajectory =
      trajroid(write("bad_trajectory.yaml", replaced(example(), "file: trajectory.csv", "file: one_point.csv")));
  EXPECT_EQ(bad_trajectory.code, 78);
  EXPECT_NE(bad_trajectory.err.find("trajectory.file"), std::string::npos) << bad_trajectory.err;
  const DaemonRun not_yaml = trajroid(write("not_yaml.yaml", "lidar: [unclosed\n"));
  EXPECT_EQ(not_yaml.code, 78) << not_yaml.err;
  EXPECT_EQ(trajroid(dir / "absent.yaml").code, 78);
  EXPECT_EQ(trajroid(TRAJROI_EXAMPLE_CONFIG, "--check-config --rate sideways").code, 78);
  fs::remove_all(dir);
}

}  // namespace
