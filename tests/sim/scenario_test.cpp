// The scenario schema: the shipped scenarios parse; every kind of bad input is refused with
// the file, the line and the key's path named.
#include "trajroi/sim/scenario.hpp"

#include <gtest/gtest.h>

#include <string>

#include "trajroi/config/yaml_reader.hpp"

namespace trajroi::sim {
namespace {

const std::string kMinimal = R"(name: tiny
start_utc: 2024-05-14T09:00:00Z
origin: {lat_deg: 36.0, lon_deg: 127.0}
world:
  boxes:
    - {name: wall, centre: [10.1, 0], size: [0.2, 40], height: 5}
trajectory:
  start: [0, 0]
  heading_deg: 0
  segments:
    - line: 2
robot:
  speed_mps: 0.5
)";

// The message of the ConfigError `text` raises (empty if it parses).
std::string error_of(const std::string& text) {
  try {
    (void)parse_scenario(text, "bad.yaml");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return {};
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(Scenario, ShippedScenariosParse) {
  for (const char* name : {"factory.yaml", "outdoor.yaml"}) {
    const Scenario s = load_scenario(std::string(TRAJROI_SOURCE_DIR) + "/config/scenarios/" + name);
    EXPECT_FALSE(s.name.empty());
    EXPECT_FALSE(s.path.segments.empty());
    EXPECT_FALSE(s.evaluation.keyframes.empty());
  }
  const Scenario f = load_scenario(std::string(TRAJROI_SOURCE_DIR) + "/config/scenarios/factory.yaml");
  ASSERT_EQ(f.evaluation.keyframes.size(), 3u);  // the paper's Table 6
  EXPECT_DOUBLE_EQ(f.evaluation.keyframes[2].position_m.x(), -28.02);
  EXPECT_DOUBLE_EQ(f.evaluation.keyframes[2].heading_rad, 1.63);
  EXPECT_DOUBLE_EQ(f.robot.speed_mps, 0.5);
  EXPECT_DOUBLE_EQ(f.evaluation.circle_diameter_m, 28.0);
  EXPECT_EQ(f.gnss.noise_h_m, 0.0);  // noise-free like the paper's Gazebo poses
  const Scenario o = load_scenario(std::string(TRAJROI_SOURCE_DIR) + "/config/scenarios/outdoor.yaml");
  ASSERT_EQ(o.gnss.faults.size(), 2u);
  EXPECT_EQ(o.gnss.faults[1].kind, GnssFault::Kind::kLost);
  EXPECT_DOUBLE_EQ(o.gnss.faults[1].from_s, 80.0);
  EXPECT_DOUBLE_EQ(o.gnss.faults[0].h_acc_m, 0.3);
}

TEST(Scenario, MinimalScenarioTakesTheDefaults) {
  const Scenario s = parse_scenario(kMinimal, "tiny.yaml");
  EXPECT_EQ(s.name, "tiny");
  EXPECT_EQ(s.start_utc_ns, 1'715'677'200'000'000'000);
  EXPECT_DOUBLE_EQ(s.lidar.rpm, 600.0);
  EXPECT_DOUBLE_EQ(s.gnss.rate_hz, 8.0);
  EXPECT_EQ(s.imu.rate_divisor, 13);
  ASSERT_EQ(s.world.boxes.size(), 1u);
  EXPECT_DOUBLE_EQ(s.world.boxes[0].size_m.y(), 40.0);
}

TEST(Scenario, UnknownKeyIsNamedWithFileAndLine) {
  const std::string e = error_of(replaced(kMinimal, "  speed_mps: 0.5", "  sped_mps: 0.5"));
  EXPECT_NE(e.find("bad.yaml:13: robot.sped_mps: unknown key"), std::string::npos) << e;
  const std::string nested = error_of(replaced(kMinimal, "height: 5}", "height: 5, colour: red}"));
  EXPECT_NE(nested.find("world.boxes[0].colour: unknown key"), std::string::npos) << nested;
}

TEST(Scenario, MissingFieldIsNamed) {
  const std::string e =
      error_of(replaced(kMinimal, "origin: {lat_deg: 36.0, lon_deg: 127.0}", "origin: {lat_deg: 36.0}"));
  EXPECT_NE(e.find("bad.yaml:3: origin.lon_deg: missing"), std::string::npos) << e;
  EXPECT_NE(error_of(replaced(kMinimal, "name: tiny\n", "")).find("name: missing"), std::string::npos);
}

TEST(Scenario, ImpossibleValuesAreRefused) {
  const std::string speed = error_of(replaced(kMinimal, "speed_mps: 0.5", "speed_mps: -0.5"));
  EXPECT_NE(speed.find("bad.yaml:13: robot.speed_mps: must be > 0 (got '-0.5')"), std::string::npos) << speed;
  const std::string one_point = error_of(replaced(kMinimal, "  segments:\n    - line: 2\n", "  segments: []\n"));
  EXPECT_NE(one_point.find("trajectory.segments: needs at least one segment"), std::string::npos) << one_point;
  const std::string below = error_of(kMinimal + "  lidar_mount: {xyz: [0, 0, -0.2]}\n");
  EXPECT_NE(below.find("robot.lidar_mount.xyz: the sensor must be above the ground"), std::string::npos) << below;
  EXPECT_NE(error_of(kMinimal + "lidar: {rpm: 50}\n").find("lidar.rpm: must be 300"), std::string::npos);
  EXPECT_NE(error_of(kMinimal + "lidar: {max_range_m: 200}\n").find("lidar.max_range_m"), std::string::npos);
  EXPECT_NE(error_of(kMinimal + "lidar: {return_mode: triple}\n")
                .find("lidar.return_mode: must be one of strongest last dual"),
            std::string::npos);
  EXPECT_NE(error_of(kMinimal + "gnss: {rate_hz: 25, baud: 9600}\n").find("gnss.baud: too slow"), std::string::npos);
  EXPECT_NE(error_of(kMinimal + "gnss:\n  faults:\n    - {kind: lost, from_s: 5, to_s: 4}\n")
                .find("gnss.faults[0].to_s: must be after from_s"),
            std::string::npos);
  EXPECT_NE(
      error_of(replaced(kMinimal, "line: 2", "line: abc")).find("trajectory.segments[0].line: must be a finite number"),
      std::string::npos);
  EXPECT_NE(error_of(replaced(kMinimal, "2024-05-14T09:00:00Z", "2024-02-30T09:00:00Z")).find("start_utc"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(kMinimal, "line: 2", "arc: {radius: 3, turn_deg: 0}")).find("turn_deg"),
            std::string::npos);
  EXPECT_NE(error_of("- just\n- a list\n").find("bad.yaml: the top level must be a mapping"), std::string::npos);
  EXPECT_NE(error_of("name: [unclosed\n").find("bad.yaml:"), std::string::npos);
}

TEST(Scenario, Iso8601Utc) {
  std::int64_t t = 0;
  ASSERT_TRUE(parse_utc_iso8601("1980-01-06T00:00:00Z", t));
  EXPECT_EQ(t, 315'964'800'000'000'000);
  ASSERT_TRUE(parse_utc_iso8601("2024-05-14T09:00:00.25Z", t));
  EXPECT_EQ(t, 1'715'677'200'250'000'000);
  EXPECT_FALSE(parse_utc_iso8601("2024-05-14 09:00:00Z", t));
  EXPECT_FALSE(parse_utc_iso8601("2024-05-14T24:00:00Z", t));
  EXPECT_FALSE(parse_utc_iso8601("2024-05-14T09:00:00", t));
}

}  // namespace
}  // namespace trajroi::sim
