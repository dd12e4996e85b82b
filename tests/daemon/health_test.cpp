// Every fault named: the health monitor turns the status counters' changes into one log line
// per fault, with its figures, within 5 s of the fault (snapshots once a second), and one when
// it ends; and tells systemd the state in words. The live tests (live_faults_test.cpp) show
// the same lines from a running daemon on real bytes.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "health_fixture.hpp"
#include "trajroi/inputs/input_source.hpp"
#include "trajroi/vlp16/packet.hpp"

namespace {

using namespace trajroi::daemon;
using namespace trajroi::daemon::health_test;

TEST(Health, AHealthyDaemonSaysNothingAndPublishes) {
  const Said said = run(live_config(), 10, healthy);
  EXPECT_TRUE(said.lines.empty()) << said.all();
  EXPECT_EQ(said.state, "publishing 10.0 sweeps/s");
}

TEST(Health, NoLidarDatagramsAreNamedWithThePortWithinFiveSecondsAndTheirReturnToo) {
  const Said said = run(live_config(), 12, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    if (t <= 8) s.lidar_packets -= 754, s.position_packets -= 1;  // nothing until 8 s
  });
  const int at = said.first("lidar: no datagrams for 3 s on UDP 0.0.0.0:2368 (data) / 8308 (position)");
  EXPECT_GE(at, 1) << said.all();
  EXPECT_LE(at, 5);
  EXPECT_EQ(said.first("lidar: datagrams arriving on UDP port 2368"), 9) << said.all();
  // A replay has no sensor to be silent.
  EXPECT_TRUE(run(
                  live_config(), 8, [](StatusSnapshot&, int) {}, false)
                  .lines.empty());
  // The state while waiting.
  // The state while waiting: every input the pose source uses, by name.
  EXPECT_EQ(run(live_config(), 3, [](StatusSnapshot&, int) {}).state,
            "waiting for LiDAR data on UDP port 2368; GNSS: no bytes from /dev/gnss; IMU: no bytes from /dev/imu");
}

TEST(Health, DatagramsOnlyFromAnotherSenderNameTheSensorAddress) {
  const Said said = run(live_config(), 6, [](StatusSnapshot& s, int) { s[Counter::kLidarRejectedSource] += 754; });
  const int at = said.first("none from sensor_address 192.168.1.201");
  EXPECT_GE(at, 1) << said.all();
  EXPECT_LE(at, 5);
  EXPECT_EQ(said.first("lidar: no datagrams"), -1) << "not silent: they come, from elsewhere";
}

TEST(Health, AnUnsupportedModelIsNamedWithTheDriversReason) {
  const Said said = run(live_config(), 3, [](StatusSnapshot& s, int) {
    reject_for_model(s, 0, 1800, "product id 0x21 (HDL-32E) is not supported");  // counted, and rejected
  });
  EXPECT_EQ(said.first("lidar: 1800 packets rejected in the last second: product id 0x21 (HDL-32E) is not supported"),
            1)
      << said.all();
  // The state names the model, not "waiting for LiDAR data": its packets do come.
  EXPECT_EQ(said.state.rfind("LiDAR: packets rejected: product id 0x21 (HDL-32E) is not supported", 0), 0U)
      << said.state;
}

TEST(Health, BytesButNoFramesSayWrongBaudRateWithTheFigures) {
  const Said said = run(live_config(), 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kGnssFrames] -= 10;
    s[Counter::kPoseFixes] -= 10;
  });
  const int at = said.first(
      "gnss: 3000 bytes in 3 s from /dev/gnss at 115200 baud but no UBX frame, and no NMEA, VN-100 ASCII or RTCM3 "
      "either: wrong baud rate? (gnss.baud)");
  EXPECT_GE(at, 1) << said.all();
  EXPECT_LE(at, 5);
}

TEST(Health, FramesOfTheOtherSensorSaySwappedDevices) {
  const Said said = run(live_config(), 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kGnssFrames] -= 10;
    s[Counter::kPoseFixes] -= 10;
    s[Counter::kGnssForeignFrames] += 40;
    s[Counter::kImuFrames] -= 40;
    s[Counter::kPoseAttitudes] -= 40;
    s[Counter::kImuForeignFrames] += 10;
  });
  EXPECT_LE(said.first("gnss: 120 VN-100 frames (and no UBX frame) in 3 s from /dev/gnss: gnss.device and "
                       "imu.device swapped?"),
            5)
      << said.all();
  EXPECT_GE(said.first("imu: 30 UBX frames (and no VN-100 frame)"), 1) << said.all();
}

TEST(Health, ASilentReceiverAndMissingOutputsAreNamed) {
  Said said = run(live_config(), 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kGnssBytes] -= 1000;
    s[Counter::kGnssFrames] -= 10;
    s[Counter::kPoseFixes] -= 10;
  });
  EXPECT_GE(said.first("gnss: no bytes for 3 s from /dev/gnss"), 1) << said.all();
  said = run(live_config(), 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kPoseFixes] -= 10;  // frames, but none a NAV-PVT
    s[Counter::kPoseAttitudes] -= 40;
    s[Counter::kPoseImuWithoutAttitude] += 40;
  });
  EXPECT_GE(said.first("gnss: 30 UBX frames in 3 s but no NAV-PVT"), 1) << said.all();
  EXPECT_GE(said.first("imu: 120 VN-100 frames in 3 s carry no YawPitchRoll, Quaternion or DCM"), 1) << said.all();
}

TEST(Health, ATrajectoryFarFromTheRobotIsNamedWithTheDistance) {
  const Said said = run(live_config(), 4, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.trajectory_id = 7;
    s.trajectory_distance_m = t < 3 ? 5012.0 : 3.0;
  });
  EXPECT_EQ(said.first("trajectory 7: the robot is 5012 m from it (more than 50 m)"), 1) << said.all();
  EXPECT_EQ(said.first("trajectory 7: the robot is back within 50 m of it"), 3) << said.all();
}

TEST(Health, ASensorClockJumpIsNamedAsSuchNotAsLoss) {
  const Said said = run(live_config(), 3, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    if (t == 2) s[Counter::kLidarClockJumps] += 1;
  });
  EXPECT_EQ(said.first("lidar: the sensor's clock jumped forward 1 time(s) in the last second"), 2) << said.all();
}

TEST(Health, AHostClockFarFromGnssTimeIsWarnedWithTheOffset) {
  const Said said = run(live_config(), 4, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.host_minus_gnss_utc_s = t < 3 ? 0.02 : -2.5;
    s.gnss_time_accuracy_s = 21e-9;
  });
  EXPECT_EQ(said.first("time: the host clock is 2.500 s behind GNSS UTC (NAV-PVT, time accuracy 2.1e-08 s; more than "
                       "time.max_gnss_offset_s 0.100 s)"),
            3)
      << said.all();
}

TEST(Health, AHostClockFarFromTheLidarsTimeIsWarnedAndItsReturnSaid) {
  DaemonConfig config = live_config();
  config.time.max_lidar_offset_s = 0.05;
  const Said said = run(config, 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.lidar[0].model = static_cast<std::int8_t>(trajroi::vlp16::Model::kVlp16);
    s.lidar[0].host_minus_utc_s = t == 3 || t == 4 ? 0.25 : 0.01;
  });
  EXPECT_EQ(said.first("time: the host clock is 0.250 s ahead of the VLP-16's PPS-locked UTC (more than "
                       "time.max_lidar_offset_s 0.050 s)"),
            3)
      << said.all();
  EXPECT_EQ(said.first("time: the host clock is within 0.050 s of the VLP-16's UTC"), 5) << said.all();
}

TEST(Health, TheLidarsPpsLostAfterItHadLockedIsNamed) {
  const Said said = run(live_config(), 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    // Synchronizing at power-up is not a loss; locked, then lost, then locked again is.
    s.lidar[0].model = static_cast<std::int8_t>(trajroi::vlp16::Model::kVlp16);
    s.lidar[0].pps_status = static_cast<std::int8_t>(t == 1 ? 1 : t == 4 ? 0 : 2);
  });
  EXPECT_EQ(said.first("lidar: the VLP-16's PPS is"), 4) << said.all();
  EXPECT_EQ(said.first("lidar: the VLP-16's PPS is absent after it had locked"), 4) << said.all();
  EXPECT_EQ(said.first("lidar: the VLP-16's PPS is locked again"), 5) << said.all();
}

TEST(Health, TheStateSaysWhyThereIsNoPose) {
  const Said said = run(live_config(), 3, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.pose_valid = false;
    s.pose_status = trajroi::pose::PoseStatus::kNoGnss;
  });
  EXPECT_EQ(said.state, "no valid pose: no GNSS fix yet from gnss.device /dev/gnss");
}

// What a port carries instead of its binary protocol is named, with the remedy.
TEST(Health, NmeaVectorNavAsciiAndRtcm3AreNamedNotBlamedOnTheBaudRate) {
  Said said = run(live_config(), 5, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kGnssFrames] -= 10;
    s[Counter::kPoseFixes] -= 10;
    s[Counter::kGnssNmea] += 8;
    s[Counter::kImuFrames] -= 40;
    s[Counter::kPoseAttitudes] -= 40;
    s[Counter::kImuVnAscii] += 40;
  });
  EXPECT_EQ(said.first("gnss: NMEA text, no UBX: 24 NMEA sentences and no UBX frame in 3 s from /dev/gnss: enable UBX "
                       "output (UBX-NAV-PVT) on this port, or set gnss.configure: true"),
            3)
      << said.all();
  EXPECT_EQ(said.first("imu: VN-100 ASCII output, no binary: 120 $VN sentences and no binary frame in 3 s from "
                       "/dev/imu: enable binary output (register 75) on this port, or set imu.configure: true"),
            3)
      << said.all();
  EXPECT_EQ(said.first("wrong baud rate"), -1) << said.all();
  EXPECT_EQ(said.state, "GNSS: NMEA text, no UBX, from /dev/gnss; IMU: VN-100 ASCII output, no binary, from /dev/imu");
  said = run(live_config(), 4, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kGnssFrames] -= 10;
    s[Counter::kPoseFixes] -= 10;
    s[Counter::kGnssRtcm3] += 3;
  });
  EXPECT_EQ(said.first("gnss: RTCM3 corrections, no UBX: 9 RTCM3 frames and no UBX frame in 3 s from /dev/gnss"), 3)
      << said.all();
}

// A device that cannot be opened is said by its input (with errno); the monitor does not add
// "no bytes" for it, and the state says it is waited for.
TEST(Health, AClosedDeviceIsWaitedForNotCalledSilent) {
  const Said said = run(live_config(), 6, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kGnssBytes] -= 1000;
    s[Counter::kGnssFrames] -= 10;
    s[Counter::kPoseFixes] -= 10;
    s.closed_streams = 1U << static_cast<unsigned>(trajroi::inputs::Stream::kGnss);
  });
  EXPECT_EQ(said.first("gnss: no bytes"), -1) << said.all();
  EXPECT_EQ(said.state, "GNSS: cannot open /dev/gnss; waiting for it");
}

// Only what the pose source uses is named: a localization's gap is a localization's, never GNSS.
TEST(Health, ALocalizationsStopReturnAndInvalidPosesAreNamedAndNoGnssIsMentioned) {
  DaemonConfig c = live_config();
  c.pose_source = trajroi::daemon::PoseSource::kLcm;
  c.lcm.pose_input = "LOC";
  const Said said = run(c, 14, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kGnssBytes] = s[Counter::kGnssFrames] = s[Counter::kPoseFixes] = 0;
    s[Counter::kImuBytes] = s[Counter::kImuFrames] = s[Counter::kPoseAttitudes] = 0;
    if (t <= 3 || t > 8) s[Counter::kPoseExternal] += 20;  // stops from 4 s to 8 s
    if (t == 11) s[Counter::kPoseExternalInvalid] += 5;
    if (t > 4 && t <= 8) {
      s.pose_valid = false;
      s.pose_status = trajroi::pose::PoseStatus::kGnssTooOld;
      s.pose_measured = 1.6;
      s.pose_limit = 1.5;
    }
    if (t == 7) {
      s.processor.sweeps_filtered -= 10;
    }
  });
  EXPECT_EQ(said.first("localization: no pose_input_t on LOC for 3 s"), 6) << said.all();
  EXPECT_EQ(said.first("localization: poses arriving on LOC"), 9) << said.all();
  EXPECT_EQ(said.first("localization: 5 of 65 poses in 3 s on LOC marked invalid"), 11) << said.all();
  EXPECT_EQ(said.first("localization: no invalid poses on LOC"), 14) << said.all();
  EXPECT_EQ(said.all().find("gnss"), std::string::npos) << said.all();
  EXPECT_EQ(said.all().find("imu"), std::string::npos) << said.all();
  // The state while it is away, in the localization's words.
  const Said away = run(c, 7, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.pose_valid = false;
    s.pose_status = trajroi::pose::PoseStatus::kGnssTooOld;
    s.pose_measured = 1.6;
    s.pose_limit = 1.5;
    if (t <= 2) s[Counter::kPoseExternal] += 20;
  });
  EXPECT_EQ(away.state, "localization: no pose_input_t on LOC");
  const Said late = run(c, 3, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    s[Counter::kPoseExternal] += 20;
    s.pose_valid = false;
    s.pose_status = trajroi::pose::PoseStatus::kGnssTooOld;
    s.pose_measured = 1.6;
    s.pose_limit = 1.5;
  });
  EXPECT_EQ(late.state,
            "no valid pose: newest localization pose too old: 1.600 s > 1.500 s (pose.max_extrapolation_s)");
}

// Datagrams that are not VLP-16 packets: named with their sizes and senders within 5 s when
// nothing else comes; summarised once a minute when mixed with the sensor's packets.
TEST(Health, DatagramsThatAreNotVlp16PacketsAreNamedWithSizesAndSenders) {
  const auto garbage = [](StatusSnapshot& s) {
    s[Counter::kLidarNotVlp16] += 500;
    s.foreign_min_size = 1;
    s.foreign_max_size = 1500;
    s.foreign_senders = {(std::uint64_t{0x7F000001} << 16) | 40000, 0, 0, 0};
  };
  Said said = run(live_config(), 4, [&](StatusSnapshot& s, int t) {
    healthy(s, t);
    s.lidar_packets = s.position_packets = 0;
    s.processor = {};
    garbage(s);
  });
  EXPECT_EQ(said.first("lidar: 500 datagrams in 1 s on UDP port 2368 and none a VLP-16 data packet (1–1500 bytes; a "
                       "VLP-16 sends 1206; from 127.0.0.1:40000)"),
            1)
      << said.all();
  EXPECT_EQ(said.first("lidar: no datagrams"), -1) << said.all();
  EXPECT_EQ(said.state.rfind("LiDAR: no VLP-16 packets on UDP port 2368, only other datagrams", 0), 0) << said.state;
  said = run(live_config(), 61, [&](StatusSnapshot& s, int t) {
    healthy(s, t);
    garbage(s);
  });
  EXPECT_EQ(said.first("lidar: 30000 datagrams in the last 60 s on UDP port 2368 were not VLP-16 data packets, beside "
                       "45240 packets (1–1500 bytes; from 127.0.0.1:40000)"),
            60)
      << said.all();
  EXPECT_EQ(said.lines.size(), 1U) << said.all();
}

// A ring that drops is named with what fell behind and the key that sizes it, as the drops
// start (not every second while they go on), and the end once the window has none.
TEST(Health, RingDropsAreNamedByRingWithTheThreadBehindAndTheirEnd) {
  const Said said = run(live_config(), 12, [](StatusSnapshot& s, int t) {
    healthy(s, t);
    if (t == 3) s[Counter::kRingDropsSweeps] += 5;
    if (t == 4) s[Counter::kRingDropsSweeps] += 2, s[Counter::kRingDropsLidar] += 40;
    if (t == 10) s[Counter::kRingDropsRecord] += 1;
  });
  EXPECT_EQ(said.first("rings: 5 items dropped in the last second: sweeps 5 (the publisher fell behind the processing "
                       "thread; buffers.sweeps): is the CPU overloaded"),
            3)
      << said.all();
  EXPECT_EQ(said.first("items dropped in the last second: lidar"), -1) << "said once as the drops start\n"
                                                                       << said.all();
  EXPECT_EQ(said.first("rings: no drops for 3 s (ring_drops.lidar 40, ring_drops.sweeps 7 in all)"), 7) << said.all();
  EXPECT_EQ(said.first("rings: 1 item dropped in the last second: record 1 (the recorder fell behind"), 10)
      << said.all();
  EXPECT_EQ(said.state, "publishing 10.0 sweeps/s");
}

// The status total is every ring's drops, the localization input's too (its counter sits apart
// from the others in the table), and nothing else.
TEST(Health, TheRingDropTotalCountsEveryRingAndNothingElse) {
  StatusSnapshot s;
  for (std::size_t c = 0; c < kCounterCount; ++c)
    s.counters[c] = 1000;
  std::uint64_t expected = 0;
  for (std::size_t c = 0; c < kCounterCount; ++c) {
    if (!counter_name(c).starts_with("ring_drops.")) continue;
    s.counters[c] = c + 1;  // each ring its own count, none 1000
    expected += c + 1;
  }
  EXPECT_EQ(s[Counter::kRingDropsPose], static_cast<std::size_t>(Counter::kRingDropsPose) + 1);
  EXPECT_EQ(s.ring_drops(), expected);
}

}  // namespace
