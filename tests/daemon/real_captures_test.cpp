// trajroid on real bytes recorded by others, the way a robot runs it: the MRPT VLP-16 capture's
// payloads sent over UDP to 127.0.0.1 at their recorded spacing, the u-blox NEO-M8P log
// (gpsd's regression suite) written into a pseudo-terminal epoch by epoch at its iTOW pace, the
// VN-100 log of the LoggerWavesInIce logger (binary output with YawPitchRoll and DCM, no time
// field) into another at its logger's pace. The trajectory is written in latitude/longitude
// through the u-blox fix. Published sweeps must come with a valid pose within 10 s, and their
// kept points must be exactly what `trajroi filter` keeps of the same sweep (decoded here from
// the pcap) placed with the same published pose. Once per pose source: gnss_imu, gnss (the
// receiver is parked: the configured initial heading, held), lcm (a test publisher stands in
// for the robot's localization: pose_input_t at 20 Hz, UTC stamps, latitude/longitude), fixed
// (LiDAR alone).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <thread>

#include "daemon_fixture.hpp"
#include "filter_check.hpp"
#include "real_rig.hpp"
#include "test_data.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/input_source.hpp"
#include "trajroi/pose/geodetic.hpp"
#include "trajroi/pose_input_t.hpp"

namespace {

using namespace daemon_test;
using std::chrono::milliseconds;
using std::chrono::seconds;

class RealCaptures : public testing::TestWithParam<const char*> {};

TEST_P(RealCaptures, SweepsArePublishedWithAValidPoseAndKeepWhatTrajroiFilterKeeps) {
  TRAJROI_REQUIRE_DATA(pcap, kPcap);
  TRAJROI_REQUIRE_DATA(ubx, kUbx);
  TRAJROI_REQUIRE_DATA(vn100, kVn100);
  const std::string source = GetParam();
  const int port_offset = source == std::string("gnss_imu") ? 0
                          : source == std::string("gnss")   ? 1
                          : source == std::string("lcm")    ? 2
                                                            : 3;
  const Rig rig(source, source, port_offset);
  Listener listener(rig.prefix);
  ASSERT_TRUE(listener.good());
  Child daemon(rig.daemon_args(), rig.daemon_log);
  ASSERT_TRUE(wait_until_running(rig.daemon_log)) << rig.logs();

  std::vector<std::string> feed = rig.pcap_feed(pcap, "3", {"--until", "5", "--linger", "2"});
  if (source == std::string("gnss_imu") || source == std::string("gnss")) {
    feed.insert(feed.end(), {"--ubx", ubx.string(), "--gnss-link", rig.gnss_link.string()});
  }
  if (source == std::string("gnss_imu")) {
    feed.insert(feed.end(), {"--vn100", vn100.string(), "--imu-link", rig.imu_link.string()});
  }
  const auto feed_start = std::chrono::steady_clock::now();
  Child feeder(TRAJROI_CLI, feed, rig.feed_log);
  // The localization: the receiver's fix, facing 45° (north-east), stamped in UTC.
  std::atomic<bool> stop_localization{false};
  std::thread localization;
  if (source == std::string("lcm")) {
    localization = std::thread([&] {
      lcm::LCM lcm(kTestLcmUrl);
      trajroi::pose_input_t m;
      m.clock = trajroi::pose_input_t::STAMP_UTC;
      m.frame = trajroi::pose_input_t::LAT_LON;
      m.position[0] = 50.1350851;
      m.position[1] = 14.4299466;
      m.position[2] = 348.86;
      const Eigen::Quaterniond q(Eigen::AngleAxisd(M_PI / 4.0, Eigen::Vector3d::UnitZ()));
      m.orientation[0] = q.w();
      m.orientation[1] = q.x();
      m.orientation[2] = q.y();
      m.orientation[3] = q.z();
      m.valid = true;
      while (!stop_localization) {
        m.t_ns = trajroi::host::realtime_ns();
        lcm.publish(rig.prefix + "_POSE_INPUT", &m);
        std::this_thread::sleep_for(milliseconds(50));
      }
    });
  }
  struct Joiner {
    std::atomic<bool>& stop;
    std::thread& thread;
    ~Joiner() {
      stop = true;
      if (thread.joinable()) thread.join();
    }
  } joiner{stop_localization, localization};

  // The first published sweep, with its valid pose, within 10 s of the sensors starting.
  ASSERT_TRUE(listener.wait_for([&] { return !listener.points.empty(); }, seconds(10))) << rig.logs();
  const double first_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - feed_start).count();
  std::printf("[ real captures ] pose source %s: first sweep published %.2f s after the feed started\n", source.c_str(),
              first_s);

  ASSERT_EQ(feeder.wait(seconds(60)), 0) << rig.logs();
  std::this_thread::sleep_for(milliseconds(300));
  rig.stop(daemon);

  const auto frames = decode_capture(pcap);
  std::lock_guard<std::mutex> lock(listener.mutex);
  std::size_t compared = 0;
  for (const auto& frame : frames) {
    const auto it = listener.points.find(static_cast<std::int64_t>(frame.index));
    if (frame.partial || it == listener.points.end()) continue;
    const trajroi::points_t& m = it->second;
    EXPECT_TRUE(m.pose.valid);
    EXPECT_EQ(m.points_in, static_cast<std::int32_t>(frame.points.size())) << "sweep " << frame.index;
    const std::string expected_heading = source == std::string("gnss_imu") ? "imu"
                                         : source == std::string("gnss")   ? "configured initial heading"
                                         : source == std::string("lcm")    ? "localization"
                                                                           : "fixed";
    EXPECT_EQ(m.pose.heading_source, expected_heading);
    // UTC from the VLP-16's own PPS-locked clock: its position packets carry a valid GPRMC,
    // 2016-01-21 08:18:02 UTC, with the PPS locked (../shared/data/README.md).
    EXPECT_EQ(m.time_source, "vlp16_pps");
    EXPECT_GE(m.sweep_start_utc_ns, 1'453'364'282'000'000'000) << "sweep " << frame.index;
    EXPECT_LE(m.sweep_start_utc_ns, 1'453'364'284'000'000'000) << "sweep " << frame.index;
    EXPECT_EQ(m.pose.utc_ns, m.sweep_start_utc_ns);
    const auto expected = filter_keeps(frame, m, listener.rois.at(m.sweep_index), rig.dir, rig.trajectory_xy);
    const auto got = daemon_keeps(frame, m);
    // Some of the sweep, not all and not nothing: the circles cut through it.
    EXPECT_GT(expected.size(), 100u) << "sweep " << frame.index;
    EXPECT_LT(expected.size(), frame.points.size() * 9 / 10) << "sweep " << frame.index;
    EXPECT_EQ(got, expected) << "sweep " << frame.index;
    std::printf("[ real captures ] sweep %llu: %zu of %zu points kept, as trajroi filter keeps\n",
                static_cast<unsigned long long>(frame.index), got.size(), frame.points.size());
    ++compared;
  }
  EXPECT_GE(compared, 2u) << rig.logs();
  ASSERT_FALSE(listener.statuses.empty());
  const trajroi::status_t& last = listener.statuses.back();
  EXPECT_EQ(last.lost_packets, 0) << rig.logs();
  EXPECT_EQ(last.decode_errors, 0) << rig.logs();
  const bool gnss = source == std::string("gnss_imu") || source == std::string("gnss");
  for (const trajroi::status_t& s : listener.statuses) {
    // Never negative; not applicable to a fixed pose; a GNSS fix's fields only for GNSS sources.
    if (source == std::string("fixed")) {
      EXPECT_TRUE(std::isnan(s.pose_age_s)) << "pose age " << s.pose_age_s;
    } else {
      EXPECT_TRUE(s.pose_age_s >= 0.0 || s.pose_age_s == -1.0) << "pose age " << s.pose_age_s;
    }
    EXPECT_EQ(s.pose_source, source == std::string("lcm") ? std::string("localization") : std::string(source));
    if (!gnss) {
      EXPECT_EQ(s.fix_type, trajroi::pose_t::NOT_APPLICABLE);
      EXPECT_TRUE(std::isnan(s.h_acc_m));
    }
  }
  for (const auto& [index, m] : listener.points) {  // the lock is held
    EXPECT_EQ(m.pose.pose_source, last.pose_source);
    if (!gnss) {
      EXPECT_EQ(m.pose.fix_type, trajroi::pose_t::NOT_APPLICABLE) << index;
      EXPECT_FALSE(m.pose.rtk_fixed) << index;
      EXPECT_TRUE(std::isnan(m.pose.h_acc_m)) << index;
    } else {
      EXPECT_GE(m.pose.fix_type, 3) << index;
      EXPECT_GT(m.pose.h_acc_m, 0.0) << index;
    }
  }
  EXPECT_EQ(last.lidar_pps_status, 2);   // locked
  EXPECT_EQ(last.lidar_gprmc_valid, 1);  // 'A'
  if (gnss) {
    // The receiver's log is from 2021-06-10: the host clock is years ahead of its GNSS time,
    // reported and warned.
    EXPECT_GT(last.host_minus_gnss_utc_s, 1e8);
    EXPECT_NE(slurp(rig.daemon_log).find("time: the host clock is"), std::string::npos) << rig.logs();
  }
  if (source == std::string("gnss_imu")) {
    // Every frame of the IMU stream had an attitude and no sensor time: placed at receipt.
    EXPECT_GT(counter(last, "pose.attitudes"), 10);
    EXPECT_EQ(counter(last, "pose.imu_without_attitude"), 0);
  }
}

INSTANTIATE_TEST_SUITE_P(PoseSources, RealCaptures, testing::Values("gnss_imu", "gnss", "lcm", "fixed"),
                         [](const testing::TestParamInfo<const char*>& p) { return std::string(p.param); });

// ---- every fault named, live -------------------------------------------------------------
//
// The daemon on real bytes (or none) with one thing wrong: the log names it, with its figures,
// within 5 s.

TEST(LiveFaults, AMissingSerialDeviceAndASilentLidarPortAreNamedWithin5s) {
  const Rig rig("missing", "gnss_imu", 4);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  EXPECT_LOGGED_WITHIN_5S(rig, "gnss: cannot open " + rig.gnss_link.string() + ": No such file or directory (errno 2)",
                          start);
  EXPECT_LOGGED_WITHIN_5S(rig, "imu: cannot open " + rig.imu_link.string() + ": No such file or directory (errno 2)",
                          start);
  EXPECT_LOGGED_WITHIN_5S(rig, "lidar: no datagrams for 3 s on UDP 0.0.0.0:" + std::to_string(rig.data_port), start);
  rig.stop(daemon);
}

TEST(LiveFaults, SwappedSerialDevicesAreNamed) {
  TRAJROI_REQUIRE_DATA(ubx, kUbx);
  TRAJROI_REQUIRE_DATA(vn100, kVn100);
  const Rig rig("swapped", "gnss_imu", 5);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  // The u-blox on the IMU's device, the VN-100 on the GNSS's.
  Child feeder(TRAJROI_CLI,
               {"feed", "--ubx", ubx.string(), "--gnss-link", rig.imu_link.string(), "--vn100", vn100.string(),
                "--imu-link", rig.gnss_link.string(), "--until", "8"},
               rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(
      rig, "(and no UBX frame) in 3 s from " + rig.gnss_link.string() + ": gnss.device and imu.device swapped?", start);
  EXPECT_LOGGED_WITHIN_5S(rig, "UBX frames (and no VN-100 frame) in 3 s from " + rig.imu_link.string(), start);
  rig.stop(daemon);
}

TEST(LiveFaults, BytesThatNeverFrameSayWrongBaudRate) {
  const Rig rig("baud", "gnss", 6);
  // What a receiver at another baud rate looks like: bytes, never a frame.
  const fs::path noise = rig.dir / "noise.bin";
  {
    std::ofstream out(noise, std::ios::binary);
    std::uint32_t x = 12345;
    for (int i = 0; i < 40000; ++i) {
      x = x * 1664525u + 1013904223u;
      out.put(static_cast<char>(x >> 24));
    }
  }
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(
      TRAJROI_CLI,
      {"feed", "--vn100", noise.string(), "--imu-link", rig.gnss_link.string(), "--vn100-rate", "20", "--until", "8"},
      rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(
      rig,
      "from " + rig.gnss_link.string() +
          " at 115200 baud but no UBX frame, and no NMEA, VN-100 ASCII or RTCM3 either: wrong baud rate?",
      start);
  rig.stop(daemon);
}

TEST(LiveFaults, AnotherLidarModelThanConfiguredIsNamedWithTheDriversReason) {
  TRAJROI_REQUIRE_DATA(hdl32e, "velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap");
  const Rig rig("model", "fixed", 7, "  model: vlp16\n");
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, rig.pcap_feed(hdl32e, "0.5"), rig.feed_log);
  // The period measured between the first two packets heard: the HDL-32E's 552.96 µs in the
  // packets' µs time stamps, 552 or 553 by which pair the daemon heard first (the feed may start
  // before the daemon listens).
  EXPECT_LOGGED_WITHIN_5S(rig, "(HDL-32E) sends HDL-32E packets (told by its timing: 55", start);
  EXPECT_LOGGED_WITHIN_5S(
      rig, " µs between packets), but lidar.model is vlp16: dropped (set lidar.model: hdl32e, or auto)", start);
  const std::string log = slurp(rig.daemon_log);
  EXPECT_TRUE(log.find("timing: 552 µs") != std::string::npos || log.find("timing: 553 µs") != std::string::npos)
      << rig.logs();
  rig.stop(daemon);
}

// lidar.model auto (the default): the HDL-32E's packets are decoded, the model said.
TEST(LiveCaptures, AnHdl32eIsToldFromItsPacketsAndDecoded) {
  TRAJROI_REQUIRE_DATA(hdl32e, "velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap");
  const Rig rig("hdl32e", "fixed", 16);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, rig.pcap_feed(hdl32e, "0.5"), rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(
      rig, "lidar: HDL-32E packets (product id 0x21), decoded with its manual's geometry (lidar.model auto)", start);
  rig.stop(daemon);
}

TEST(LiveFaults, DatagramsFromAnotherAddressNameTheSensorAddress) {
  TRAJROI_REQUIRE_DATA(pcap, kPcap);
  const Rig rig("sender", "fixed", 8, "  sensor_address: 127.0.0.2\n");
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, rig.pcap_feed(pcap, "1", {"--from", "127.0.0.1"}), rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(rig, "none from sensor_address 127.0.0.2: is lidar.sensor_address the sensor's?", start);
  rig.stop(daemon);
}

TEST(LiveFaults, ATrajectoryFarFromTheRobotIsNamedWithItsDistance) {
  TRAJROI_REQUIRE_DATA(pcap, kPcap);
  const Rig rig("far", "fixed", 9, "", "{xyz: [5000, 0, 0]}");
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, rig.pcap_feed(pcap, "0.5"), rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(rig, "trajectory 0: the robot is 4996 m from it (more than 50 m)", start);
  rig.stop(daemon);
}

// A rejected trajectory message is said even while withheld sweeps are being warned about:
// each has its own rate limit (it was swallowed by the sweeps' before).
TEST(LiveFaults, ARejectedTrajectoryMessageIsSaidAmidWithheldSweepWarnings) {
  TRAJROI_REQUIRE_DATA(pcap, kPcap);
  const Rig rig("rejected", "gnss_imu", 11);  // no GNSS, no IMU fed: every sweep is withheld
  Listener listener(rig.prefix);
  ASSERT_TRUE(listener.good());
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, rig.pcap_feed(pcap, "0.5"), rig.feed_log);
  ASSERT_GE(seconds_until_logged(rig.daemon_log, "withheld: no valid pose (no GNSS fix yet from gnss.device ", start,
                                 seconds(5)),
            0.0)
      << rig.logs();
  trajroi::trajectory_t bad;
  bad.id = 0;  // ids are > 0
  bad.coordinates = trajroi::trajectory_t::GLOBAL_XY;
  bad.num_waypoints = 2;
  bad.u = {0.0, 10.0};
  bad.v = {0.0, 0.0};
  const auto sent = std::chrono::steady_clock::now();
  listener.publish_trajectory(bad);
  EXPECT_GE(
      seconds_until_logged(rig.daemon_log, "trajectory on " + rig.prefix + "_TRAJECTORY rejected", sent, seconds(2)),
      0.0)
      << rig.logs();
  rig.stop(daemon);
}

// The sensor's port is this daemon's alone: a second one on it stops at start, naming it.
TEST(LiveFaults, ASecondDaemonOnTheSameLidarPortFailsAtStartNamingThePort) {
  const Rig rig("exclusive", "fixed", 10);
  Child first(rig.daemon_args(), rig.daemon_log);
  ASSERT_TRUE(wait_until_running(rig.daemon_log)) << rig.logs();
  const fs::path second_log = rig.dir / "second.log";
  Child second(rig.daemon_args(), second_log);
  const int code = second.wait(seconds(5));
  EXPECT_NE(code, 0);
  EXPECT_NE(code, -1) << "the second daemon did not stop";
  const std::string said = slurp(second_log);
  EXPECT_NE(said.find("UDP 0.0.0.0:" + std::to_string(rig.data_port) + ": bind: Address already in use"),
            std::string::npos)
      << said;
  EXPECT_TRUE(first.running()) << "the first daemon goes on";
  rig.stop(first);
}

}  // namespace
