// Several LiDARs' health: the state says the merged rate and the sensors'; every line that names
// a sensor (silent, no datagrams, its model, its rejected packets, its clock, its PPS) names the
// right one with its address and port, not the first sensor's or "the VLP-16".
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "health_fixture.hpp"
#include "trajroi/vlp16/model.hpp"
#include "trajroi/vlp16/packet.hpp"

namespace {

using namespace trajroi::daemon;
using namespace trajroi::daemon::health_test;

// Several LiDARs: the state says how many and how they go out; one falling silent is named with
// its address and port, in the log once (whether a sweep or a snapshot says it first) and in the
// state while it lasts, and its return too.
TEST(Health, ASilentLidarOfSeveralIsNamedOnceAndInTheStateWhileItLasts) {
  const DaemonConfig c = two_lidars();
  HealthMonitor monitor(c, true, 0);
  StatusSnapshot s;
  s.trajectory_distance_m = std::numeric_limits<double>::quiet_NaN();
  s.host_minus_gnss_utc_s = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::string> said;
  for (int t = 1; t <= 6; ++t) {
    s.steady_ns = t * kSecond;
    healthy(s, t);
    s.processor.sweeps += 10;  // two sensors at 10 Hz, their sweeps merged two by two
    s.processor.sweeps_filtered += 10;
    s[Counter::kMergePublished] += 10;
    s.silent_lidars = t >= 3 && t <= 4 ? 2U : 0U;
    if (t == 3) {  // the first sweep without it, before the snapshot
      for (const HealthLine& l : monitor.silent_lidars(2U))
        said.push_back(l.text);
    }
    for (const HealthLine& l : monitor.update(s))
      said.push_back(l.text);
    if (t == 2) {
      // The rate a subscriber sees, and the sensors' sweeps in it.
      EXPECT_EQ(monitor.state(), "publishing 10.0 merged sweeps/s of 2 LiDARs (20.0 sensor sweeps/s)");
    }
    if (t == 4) {
      EXPECT_EQ(monitor.state(), "LiDAR rear (192.168.1.202 → UDP 2368): silent, not merged");
    }
  }
  ASSERT_EQ(said.size(), 2U);
  EXPECT_EQ(said[0].rfind("lidar: rear (192.168.1.202 → UDP 2368) silent: no sweep for more than 0.50 s", 0), 0U)
      << said[0];
  EXPECT_EQ(said[1], "lidar: rear (192.168.1.202 → UDP 2368) sends sweeps again");
}

// Published each alone, every sensor's sweep is a message: the state's rate is theirs.
TEST(Health, SeveralLidarsPublishedEachAloneSayTheSensorsRate) {
  DaemonConfig c = two_lidars();
  c.lidar_merge.per_sensor = true;
  const Said said = run(c, 3, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.processor.sweeps += 10;
    s.processor.sweeps_filtered += 10;
  });
  EXPECT_EQ(said.state, "publishing 20.0 sweeps/s of 2 LiDARs (each alone)");
}

// With several LiDARs the lines that say nothing (or nothing right) arrives name every
// sensor's sockets and address, not the first sensor's alone.
TEST(Health, WithSeveralLidarsNoDatagramsNameEverySensorsPortsAndAddresses) {
  DaemonConfig c = live_config();
  DaemonConfig::Lidar front = c.lidar;
  front.name = "front";
  front.sensor_address = "127.0.0.2";
  DaemonConfig::Lidar rear = front;
  rear.name = "rear";
  rear.sensor_address = "127.0.0.3";
  rear.data_port = 2369;
  rear.position_port = 8309;
  DaemonConfig::Lidar top = rear;
  top.name = "top";
  top.sensor_address = "127.0.0.4";
  c.lidar = front;
  c.lidars = {front, rear, top};
  Said said = run(c, 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.lidar_packets -= 754, s.position_packets -= 1;
  });
  EXPECT_GE(said.first("lidar: no datagrams for 3 s on UDP 0.0.0.0:2368 / 8308 (front), 0.0.0.0:2369 / 8309 (rear, "
                       "top): sensor off"),
            1)
      << said.all();
  EXPECT_EQ(said.state.rfind("waiting for LiDAR data on UDP ports 2368, 2369", 0), 0U) << said.state;
  said = run(c, 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.lidar_packets -= 754, s.position_packets -= 1;
    s[Counter::kLidarRejectedSource] += 754;
  });
  EXPECT_GE(said.first("on UDP ports 2368, 2369, none from the sensor_address of front 127.0.0.2, rear 127.0.0.3, "
                       "top 127.0.0.4: is lidars[].sensor_address the sensor's?"),
            1)
      << said.all();
}

// Several LiDARs: what one sensor's packets or clock say is named with that sensor (the others
// healthy meanwhile), not put down to the first one or to "the VLP-16".
TEST(Health, EachLidarOfSeveralIsNamedWithItsModelItsRejectedPacketsItsClockAndItsPps) {
  DaemonConfig c = two_lidars();
  c.time.max_lidar_offset_s = 0.05;
  const Said said = run(c, 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.lidar_count = 2;
    s.lidar[0].accepted += 754;
    s.lidar[0].model = static_cast<std::int8_t>(trajroi::vlp16::Model::kVlp16);
    s.lidar[0].pps_status = 2;
    s.lidar[0].host_minus_utc_s = 0.01;
    if (t <= 2) {  // the rear a VLP-32C, its PPS locked, then its clock off and its PPS lost
      s.lidar[1].accepted += 1500;
      s.lidar[1].model = static_cast<std::int8_t>(trajroi::vlp16::Model::kVlp32c);
    }
    s.lidar[1].pps_status = static_cast<std::int8_t>(t == 5 ? 0 : 2);
    s.lidar[1].host_minus_utc_s = t >= 3 ? -0.25 : 0.01;
    // then packets of a model trajroid does not decode
    if (t >= 3) reject_for_model(s, 1, 1500, "product id 0x63 (VLS-128) is not supported");
  });
  EXPECT_EQ(said.first("lidar: front (192.168.1.201 → UDP 2368): VLP-16 packets (product id 0x22), decoded with its "
                       "manual's geometry (lidars[0].model auto)"),
            1)
      << said.all();
  EXPECT_EQ(said.first("lidar: rear (192.168.1.202 → UDP 2368): VLP-32C packets (product id 0x28), decoded with its "
                       "manual's geometry (lidars[1].model auto)"),
            1)
      << said.all();
  EXPECT_EQ(said.first("lidar: rear (192.168.1.202 → UDP 2368): 1500 packets rejected in the last second: product id "
                       "0x63 (VLS-128) is not supported"),
            3)
      << said.all();
  EXPECT_EQ(said.first("time: the host clock is 0.250 s behind the rear LiDAR's (192.168.1.202 → UDP 2368) "
                       "PPS-locked UTC (more than time.max_lidar_offset_s 0.050 s)"),
            3)
      << said.all();
  EXPECT_EQ(said.first("lidar: the rear LiDAR's (192.168.1.202 → UDP 2368) PPS is absent after it had locked"), 5)
      << said.all();
  EXPECT_EQ(said.first("lidar: every LiDAR's PPS is locked again"), 6) << said.all();
  EXPECT_EQ(said.first("front LiDAR's"), -1) << "the front's clock and PPS are fine: " << said.all();
  // The state names the rear's rejected packets; the front's sweeps still go out.
  EXPECT_EQ(said.state.rfind("LiDAR rear (192.168.1.202 → UDP 2368): packets rejected: product id 0x63 (VLS-128) is "
                             "not supported",
                             0),
            0U)
      << said.state;
}

}  // namespace
