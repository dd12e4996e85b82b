// trajroid's configuration: the documented example reads, and every kind of mistake stops the
// daemon with exit code 78 and a message naming the file, line, key and value.
#include "trajroi/daemon/config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "daemon_fixture.hpp"
#include "test_data.hpp"

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
  EXPECT_DOUBLE_EQ(c.lidar.robot_from_lidar.translation().z(), 0.0);
  EXPECT_EQ(c.pose_mode, PoseMode::kPerFiring);
  EXPECT_EQ(c.pose_source, PoseSource::kGnssImu);
  EXPECT_EQ(c.gate.max_extrapolation_ns, 500'000'000);
  EXPECT_DOUBLE_EQ(c.gate.max_h_acc_m, 5.0);
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
      error_of(replaced(example(), "  max_h_acc_m: 5.0", "  max_h_acc_m: -1")).find("pose.max_h_acc_m: must be > 0"),
      std::string::npos);
  EXPECT_NE(error_of(replaced(example(), "    lidar: {policy: other}", "    lidar: {policy: fifo, priority: 120}"))
                .find("realtime.threads.lidar.priority"),
            std::string::npos);
  EXPECT_NE(
      error_of(replaced(example(), "  spacing_ratio: 0.25", "  spacing_ratio: 0.000001")).find("roi.spacing_ratio"),
      std::string::npos);
  EXPECT_NE(error_of(replaced(example(), "global_frame:", "global_fram:")).find("global_frame"), std::string::npos);
  const std::string renamed = error_of(replaced(example(), "  max_h_acc_m: 5.0", "  require_rtk_fixed: true"));
  EXPECT_NE(renamed.find("pose.require_rtk_fixed: renamed: pose.require_rtk: fixed (or float, none)"),
            std::string::npos)
      << renamed;
  EXPECT_NE(error_of(replaced(example(), "  chrony_shm: none", "  chrony_shm: 2.5"))
                .find("time.chrony_shm: must be none or an SHM unit 0 … 15"),
            std::string::npos);
}

// The documented defaults are the code's: the example (every key, "with the value the daemon
// uses when the key is left out") reads exactly as a file holding only the required keys.
TEST(DaemonConfig, EveryDocumentedDefaultIsTheCodesDefault) {
  const DaemonConfig documented = parse_daemon_config(example(), fs::path(TRAJROI_EXAMPLE_CONFIG));
  const DaemonConfig omitted = parse_daemon_config(
      "global_frame:\n  origin: {lat_deg: 36.3721, lon_deg: 127.3604, height_m: 60.0}\n"
      "trajectory:\n  file: trajectory.csv\n",
      fs::path(TRAJROI_EXAMPLE_CONFIG));
  const std::string a = describe(documented);
  const std::string b = describe(omitted);
  EXPECT_EQ(a, b);
  // And describe() covers every key the file documents (so the comparison above is whole):
  // each "key:" line of the file, as its dotted path, is one of describe()'s keys.
  std::istringstream lines(example());
  std::vector<std::pair<std::size_t, std::string>> path;  // indent, key
  std::string line;
  std::size_t keys = 0;
  while (std::getline(lines, line)) {
    const std::size_t indent = line.find_first_not_of(' ');
    if (indent == std::string::npos || line[indent] == '#') continue;
    const std::size_t colon = line.find(':', indent);
    ASSERT_NE(colon, std::string::npos) << line;
    const std::string key = line.substr(indent, colon - indent);
    while (!path.empty() && path.back().first >= indent)
      path.pop_back();
    std::string dotted;
    for (const auto& [unused, parent] : path)
      dotted += parent + ".";
    dotted += key;
    std::string value = line.substr(colon + 1);
    value = value.substr(0, value.find('#'));
    if (value.find_first_not_of(' ') == std::string::npos) {
      path.emplace_back(indent, key);  // a section
      continue;
    }
    ++keys;
    EXPECT_NE(("\n" + a).find("\n" + dotted + ": "), std::string::npos) << dotted << " is documented but not described";
  }
  EXPECT_GT(keys, 60u);
}

TEST(DaemonConfig, ValuesThatWouldFailAtRunTimeAreRefusedAtStart) {
  const auto refused = [](const std::string& from, const std::string& to, const std::string& expected) {
    const std::string e = error_of(replaced(example(), from, to));
    EXPECT_NE(e.find(expected), std::string::npos) << to << " → " << e;
  };
  refused("  baud: 115200\n  antenna", "  baud: 123457\n  antenna", "gnss.baud: must be one of 1200, 2400");
  refused("  url: udpm://239.255.76.67:7667?ttl=0", "  url: udpm://239.255.76.67:99999?ttl=0",
          "port '99999' is not a UDP port");
  refused("  url: udpm://239.255.76.67:7667?ttl=0", "  url: udpm://10.0.0.1:7667", "not a multicast address");
  refused("  url: udpm://239.255.76.67:7667?ttl=0", "  url: udp://239.255.76.67:7667", "provider 'udp'");
  refused("  url: udpm://239.255.76.67:7667?ttl=0", "  url: udpm://239.255.76.67:7667?ttl=300", "ttl '300'");
  // A device that exists but is no serial port; one that does not exist yet is fine (a USB
  // receiver may appear after the start).
  refused("  device: \"\"                     # e.g. /dev/ttyACM0", "  device: /etc/hostname  # e.g. /dev/ttyACM0",
          "gnss.device: exists but is not a character device");
  EXPECT_EQ(error_of(replaced(example(), "  device: \"\"                     # e.g. /dev/ttyACM0",
                              "  device: /dev/ttyTRAJROI_NOT_YET  # e.g. /dev/ttyACM0")),
            "");
  EXPECT_EQ(error_of(replaced(example(), "  device: \"\"                     # e.g. /dev/ttyACM0",
                              "  device: /dev/null  # e.g. /dev/ttyACM0")),
            "");
  refused("  initial_heading_deg: none", "  initial_heading_deg: 400", "initial_heading_deg");
  refused("  source: gnss_imu", "  source: compass", "pose.source");
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
  // --version needs no configuration.
  EXPECT_EQ(daemon_test::run_command(std::string(TRAJROID) + " --version | grep -qx 'trajroid " TRAJROI_VERSION "'"),
            0);
  const DaemonRun bad_url = trajroid(TRAJROI_EXAMPLE_CONFIG, "--check-config --lcm-url udpm://239.255.76.67:99999");
  EXPECT_EQ(bad_url.code, 78);
  EXPECT_NE(bad_url.err.find("99999"), std::string::npos) << bad_url.err;
  const DaemonRun bad_baud =
      trajroid(write("bad_baud.yaml", replaced(example(), "  baud: 115200\n  antenna", "  baud: 123457\n  antenna")),
               "--check-config");
  EXPECT_EQ(bad_baud.code, 78);
  EXPECT_NE(bad_baud.err.find("gnss.baud"), std::string::npos) << bad_baud.err;
  EXPECT_NE(bad_baud.err.find("123457"), std::string::npos) << bad_baud.err;
  // Degrees read as metres: refused; the same file declared as lat,lon: accepted.
  std::ofstream(dir / "degrees.csv") << "36.3721,127.3604\n36.3731,127.3614\n";
  const DaemonRun degrees = trajroid(
      write("degrees.yaml", replaced(example(), "file: trajectory.csv", "file: degrees.csv")), "--check-config");
  EXPECT_EQ(degrees.code, 78);
  EXPECT_NE(degrees.err.find("look like degrees"), std::string::npos) << degrees.err;
  std::ofstream(dir / "lat_lon.csv") << "lat,lon\n36.3721,127.3604\n36.3731,127.3614\n";
  EXPECT_EQ(trajroid(write("lat_lon.yaml", replaced(example(), "file: trajectory.csv", "file: lat_lon.csv")),
                     "--check-config")
                .code,
            0);
  fs::remove_all(dir);
}

// A LiDAR's calibration file is part of the configuration: malformed, or of another model's
// laser count, it is a configuration error naming the LiDAR's key (the second of lidars:),
// the file and its line, for --check-config as for a start.
TEST(DaemonConfig, ASecondLidarsBadCalibrationIsAConfigurationErrorNamingItsKeyFileAndLine) {
  const fs::path dir = fs::temp_directory_path() / ("trajroid_calibration_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "trajectory.csv") << "0,0\n10,0\n";
  std::ofstream(dir / "broken.yaml") << "lasers:\n  - {laser_id: 0, vert_correction: abc}\n";
  const auto config = [&](const std::string& name, const std::string& rear_extra) {
    std::ofstream(dir / name) << "global_frame: {origin: {lat_deg: 50, lon_deg: 14, height_m: 0}}\n"
                                 "trajectory: {file: trajectory.csv}\n"
                                 "lidars:\n"
                                 "  - {name: front, sensor_address: 127.0.0.2}\n"
                                 "  - {name: rear, sensor_address: 127.0.0.3, "
                              << rear_extra << "}\n";
    return dir / name;
  };
  const fs::path malformed = config("malformed.yaml", "calibration: broken.yaml");
  for (const char* mode : {"--check-config", ""}) {
    const DaemonRun r = trajroid(malformed, mode);
    EXPECT_EQ(r.code, 78) << r.err;
    EXPECT_NE(r.err.find("lidars[1].calibration: " + (dir / "broken.yaml").string() + ":2:"), std::string::npos)
        << r.err;
  }
  TRAJROI_REQUIRE_DATA(vlp16_calibration, "velodyne/vlp16/nebula_VLP16_calibration.yaml");
  const fs::path sixteen = config("sixteen.yaml", "model: vlp32c, calibration: " + vlp16_calibration.string());
  for (const char* mode : {"--check-config", ""}) {
    const DaemonRun r = trajroid(sixteen, mode);
    EXPECT_EQ(r.code, 78) << r.err;
    EXPECT_NE(r.err.find(": 16 lasers, but a VLP-32C (lidars[1].model vlp32c) has 32"), std::string::npos) << r.err;
  }
  fs::remove_all(dir);
}

}  // namespace

namespace {

// The reference page (docs/configuration.md) holds, below its marker, exactly what the daemon's
// key table generates; and that table's keys are the ones --check-config reports.
TEST(Config, TheReferencePageIsTheDaemonsOwnTable) {
  const std::string page = daemon_test::slurp(TRAJROI_CONFIG_DOC);
  const std::string marker = "<!-- generated: trajroid --config-reference -->\n";
  const std::size_t at = page.find(marker);
  ASSERT_NE(at, std::string::npos) << "docs/configuration.md has no generated part";
  EXPECT_EQ(page.substr(at + marker.size()), config_reference())
      << "regenerate it: trajroid --config-reference (below the marker)";

  std::vector<std::string> described, referenced;
  std::istringstream lines(describe(parse_daemon_config(example(), fs::path(TRAJROI_EXAMPLE_CONFIG))));
  for (std::string line; std::getline(lines, line);)
    described.push_back(line.substr(0, line.find(':')));
  std::istringstream rows(config_reference());
  for (std::string line; std::getline(rows, line);) {
    if (line.rfind("| `", 0) == 0) referenced.push_back(line.substr(3, line.find('`', 3) - 3));
  }
  EXPECT_GT(described.size(), 60u);
  EXPECT_EQ(referenced, described);
}

}  // namespace

namespace {

// --check-config passes a configuration whose devices are not plugged in (a USB receiver may come
// later) and says which are absent and that the daemon will wait for them.
TEST(DaemonConfig, CheckConfigNamesAbsentDevicesAndSaysTheDaemonWillWait) {
  const fs::path dir = fs::temp_directory_path() / ("trajroid_absent_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "trajectory.csv") << "0,0\n10,0\n";
  std::string text = replaced(example(), "  device: \"\"                     # e.g. /dev/ttyACM0",
                              "  device: /nonexistent/gnss  # e.g. /dev/ttyACM0");
  text = replaced(text, "  device: \"\"                     # e.g. /dev/ttyUSB0", "  device: /dev/null  # e.g.");
  std::ofstream(dir / "absent.yaml") << text;
  const fs::path out = dir / "out.txt";
  const int code = daemon_test::run_command(std::string(TRAJROID) + " --config " + (dir / "absent.yaml").string() +
                                            " --check-config >" + out.string() + " 2>&1");
  const std::string said = daemon_test::slurp(out);
  EXPECT_EQ(code, 0) << said;
  EXPECT_NE(said.find("gnss.device /nonexistent/gnss does not exist now: trajroid will start and wait for it"),
            std::string::npos)
      << said;
  EXPECT_EQ(said.find("imu.device /dev/null does not exist"), std::string::npos) << said;
  EXPECT_NE(said.find("configuration OK"), std::string::npos) << said;
  fs::remove_all(dir);
}

}  // namespace
