// lidars: several LiDARs, each with the keys of lidar: and a name; and what a robot's
// configuration can get wrong with them.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "trajroi/daemon/config.hpp"

namespace {

using trajroi::daemon::DaemonConfig;
using trajroi::daemon::describe;
using trajroi::daemon::parse_daemon_config;

const std::string kHead =
    "global_frame:\n  origin: {lat_deg: 50, lon_deg: 14, height_m: 300}\ntrajectory:\n  file: t.csv\n";

std::string error_of(const std::string& text) {
  try {
    (void)parse_daemon_config(text, "robot.yaml");
  } catch (const trajroi::config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigLidars, EachSensorHasItsKeysNameAndMounting) {
  const DaemonConfig c = parse_daemon_config(kHead +
                                                 "lidars:\n"
                                                 "  - name: front\n"
                                                 "    sensor_address: 192.168.1.201\n"
                                                 "    mounting: {xyz: [0.6, 0, 0.9]}\n"
                                                 "    model: vlp16\n"
                                                 "  - name: rear\n"
                                                 "    sensor_address: 192.168.1.202\n"
                                                 "    mounting: {xyz: [-0.6, 0, 0.9], yaw_deg: 180}\n"
                                                 "    max_range_m: 40\n"
                                                 "  - name: top\n"
                                                 "    data_port: 2370\n"
                                                 "    position_port: 8310\n"
                                                 "lidar_merge: {max_wait_s: 0.05, publish: merged}\n",
                                             "robot.yaml");
  ASSERT_EQ(c.lidars.size(), 3U);
  EXPECT_EQ(c.lidars[0].name, "front");
  EXPECT_EQ(c.lidars[0].model, "vlp16");
  EXPECT_EQ(c.lidars[1].name, "rear");
  EXPECT_DOUBLE_EQ(c.lidars[1].max_range_m, 40.0);
  EXPECT_DOUBLE_EQ(c.lidars[0].max_range_m, 130.0);  // each entry from the defaults, not from another
  EXPECT_NEAR(c.lidars[1].robot_from_lidar.translation().x(), -0.6, 1e-12);
  EXPECT_NEAR(c.lidars[1].robot_from_lidar.linear()(0, 0), -1.0, 1e-12);  // turned 180°
  EXPECT_EQ(c.lidars[2].data_port, 2370);
  EXPECT_EQ(c.lidar.name, "front");  // lidar: is the first
  EXPECT_DOUBLE_EQ(c.lidar_merge.max_wait_s, 0.05);
  EXPECT_FALSE(c.lidar_merge.per_sensor);
  const std::string said = describe(c);
  EXPECT_NE(said.find("lidars[1].name: rear"), std::string::npos) << said;
  EXPECT_NE(said.find("lidars[2].data_port: 2370"), std::string::npos) << said;
}

TEST(ConfigLidars, OneLidarIsTheOneOfLidarsNamedLidar) {
  const DaemonConfig c = parse_daemon_config(kHead + "lidar:\n  data_port: 2400\n", "robot.yaml");
  ASSERT_EQ(c.lidars.size(), 1U);
  EXPECT_EQ(c.lidars[0].name, "lidar");
  EXPECT_EQ(c.lidars[0].data_port, 2400);
}

TEST(ConfigLidars, TwoSensorsOnOnePortWithoutAddressesAreAnErrorNamingBoth) {
  const std::string e = error_of(kHead +
                                 "lidars:\n"
                                 "  - name: front\n"
                                 "  - name: rear\n"
                                 "    sensor_address: 10.0.0.2\n");
  EXPECT_NE(e.find("robot.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("front and rear share UDP ports 2368/8308 without sensor_address"), std::string::npos) << e;
  const std::string same = error_of(kHead +
                                    "lidars:\n"
                                    "  - {name: a, sensor_address: 10.0.0.2}\n"
                                    "  - {name: b, sensor_address: 10.0.0.2}\n");
  EXPECT_NE(same.find("a and b share UDP port 2368 and sensor_address 10.0.0.2"), std::string::npos) << same;
  const std::string crossed = error_of(kHead +
                                       "lidars:\n"
                                       "  - {name: a, data_port: 2368, position_port: 8308}\n"
                                       "  - {name: b, data_port: 8308, position_port: 2369}\n");
  EXPECT_NE(crossed.find("a and b: one's data port is the other's position port"), std::string::npos) << crossed;
  const std::string half = error_of(kHead +
                                    "lidars:\n"
                                    "  - {name: a, sensor_address: 10.0.0.2}\n"
                                    "  - {name: b, sensor_address: 10.0.0.3, position_port: 8309}\n");
  EXPECT_NE(half.find("share one port but not the other"), std::string::npos) << half;
}

TEST(ConfigLidars, NamesMountingsAndTheListItselfAreChecked) {
  EXPECT_NE(error_of(kHead + "lidars:\n  - {data_port: 2368}\n").find("lidars[0].name"), std::string::npos);
  EXPECT_NE(error_of(kHead + "lidars:\n  - {name: 'front lidar'}\n").find("must be 1 … 32 letters"), std::string::npos);
  EXPECT_NE(error_of(kHead + "lidars:\n  - {name: a, sensor_address: 10.0.0.2}\n  - {name: a, sensor_address: "
                             "10.0.0.3}\n")
                .find("lidars[1].name: is the name of another sensor"),
            std::string::npos);
  // Non-finite mountings: named with the entry.
  const std::string nan =
      error_of(kHead +
               "lidars:\n  - name: a\n    mounting: {xyz: [0, .nan, 0.5]}\n  - {name: b, data_port: 2370, "
               "position_port: 8310}\n");
  EXPECT_NE(nan.find("lidars[0].mounting"), std::string::npos) << nan;
  EXPECT_NE(error_of(kHead + "lidars:\n  - name: a\n    mounting: {yaw_deg: .inf}\n").find("finite"),
            std::string::npos);
  EXPECT_NE(error_of(kHead + "lidar: {data_port: 2368}\nlidars:\n  - {name: a}\n").find("not both"), std::string::npos);
  EXPECT_NE(error_of(kHead + "lidars: []\n").find("must list 1"), std::string::npos);
  EXPECT_NE(error_of(kHead + "lidars:\n  - name: a\n    min_range_m: 5\n    max_range_m: 2\n").find("lidars[0]"),
            std::string::npos);
  EXPECT_NE(error_of(kHead + "lidars:\n  - {name: a, data_prot: 2368}\n").find("lidars[0].data_prot: unknown key"),
            std::string::npos);
}

}  // namespace
