// The pose's messages, live: a withheld sweep's reason in the pose source's words with the
// setting that would change it, each new reason said as it appears; every accepted trajectory
// under a new id that subscribers see; a robot's localization published with the project's
// Python module (examples/localization.py), used, and its stop, return and invalid poses named;
// a recording announced and reported; `trajroi watch`'s closing figures. The LiDAR is the
// VLP-16 capture of the data set, or, where a case needs longer than its 0.4 s, the simulated
// corridor's capture (tests/daemon/corridor.yaml) sent the same way.
#include <cmath>

#include "real_rig.hpp"
#include "test_data.hpp"

namespace {

using namespace daemon_test;

trajroi::status_t last_status(Listener& listener) {
  std::lock_guard<std::mutex> lock(listener.mutex);
  return listener.statuses.empty() ? trajroi::status_t{} : listener.statuses.back();
}

// Seconds since `start` at which `text` first shows in `log`'s lines (-1: absent).
double logged_at(const fs::path& log, const std::string& text, std::chrono::steady_clock::time_point start,
                 std::chrono::milliseconds timeout) {
  return seconds_until_logged(log, text, start, timeout);
}

// The corridor's capture (29 s of VLP-16 data) played to `rig` for `seconds`.
std::vector<std::string> corridor_lidar(const Rig& rig, const std::string& seconds) {
  return rig.pcap_feed(corridor_run() / "lidar.pcap", "0.5", {"--until", seconds});
}

// The robot's localization: examples/localization.py, parked on the rig's trajectory.
Child localization(const Rig& rig, const fs::path& output, std::vector<std::string> extra) {
  std::vector<std::string> args{std::string("PYTHONPATH=") + TRAJROI_PYTHON_PATH,
                                "python3",
                                std::string(TRAJROI_EXAMPLES_DIR) + "/localization.py",
                                "--url",
                                kTestLcmUrl,
                                "--channel",
                                rig.prefix + "_POSE_INPUT",
                                "--trajectory-channel",
                                rig.prefix + "_TRAJECTORY",
                                "--lat",
                                "50.13505",
                                "--lon",
                                "14.42995",
                                "--height",
                                "348",
                                "--yaw-deg",
                                "90"};
  args.insert(args.end(), extra.begin(), extra.end());
  return Child("/usr/bin/env", args, output);
}

TEST(LivePoseMessages, AParkedRobotOnGnssAloneIsToldTheSettingsThatGiveItAHeading) {
  TRAJROI_REQUIRE_DATA(pcap, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  TRAJROI_REQUIRE_DATA(ubx, "ublox/gpsd/ublox-neo-m8p.log");
  const Rig rig("parked", "gnss", 1);
  std::string text = slurp(rig.config);
  text.replace(text.find("  gnss_heading: {initial_heading_deg: 30}\n"), 41, "");  // none configured
  std::ofstream(rig.config) << text;
  Listener listener(rig.prefix);
  Child daemon(rig.daemon_args(), rig.daemon_log);
  const auto start = std::chrono::steady_clock::now();
  Child feeder(TRAJROI_CLI,
               rig.pcap_feed(pcap, "2", {"--until", "6", "--ubx", ubx.string(), "--gnss-link", rig.gnss_link.string()}),
               rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(
      rig,
      "withheld: no valid pose (no GNSS heading yet: the robot has not moved faster than "
      "pose.gnss_heading.min_speed_mps (1.00 m/s) and no moving-base heading came; to start parked, "
      "set pose.gnss_heading.initial_heading_deg)",
      start);
  // The state says it too, while the receiver is still there.
  EXPECT_TRUE(listener.wait_for(
      [&] {
        return !listener.statuses.empty() &&
               listener.statuses.back().state.find("no valid pose: no GNSS heading yet") != std::string::npos;
      },
      seconds(3)))
      << last_status(listener).state;
  EXPECT_EQ(last_status(listener).pose_source, "gnss");
  ASSERT_EQ(feeder.wait(seconds(30)), 0) << rig.logs();
  rig.stop(daemon);
}

// The first reason (no fix) is being held back when the second (the accuracy gate) appears: the
// second is said at once all the same.
TEST(LivePoseMessages, ANewWithheldReasonIsSaidAtOnceWhileAnotherIsHeldBack) {
  TRAJROI_REQUIRE_DATA(ubx, "ublox/gpsd/ublox-neo-m8p.log");
  TRAJROI_REQUIRE_DATA(vn100, "vectornav/LoggerWavesInIce_F00379.raw");
  (void)corridor_run();  // simulated before the clock starts (slow under sanitizers)
  const Rig rig("reasons", "gnss_imu", 2);
  rig.add_under("pose", "  max_h_acc_m: 0.01\n");
  rig.add_under("logging", "  warning_interval_s: 30\n");  // a held reason would stay held for the whole test
  Child daemon(rig.daemon_args(), rig.daemon_log);
  const auto start = std::chrono::steady_clock::now();
  Child lidar(TRAJROI_CLI, corridor_lidar(rig, "14"), rig.feed_log);
  const double first = logged_at(rig.daemon_log, "withheld: no valid pose (no GNSS fix yet from gnss.device ", start,
                                 milliseconds(6000));
  ASSERT_GE(first, 0.0) << rig.logs();
  std::this_thread::sleep_for(seconds(1));
  const auto gnss_start = std::chrono::steady_clock::now();
  Child serial(TRAJROI_CLI,
               {"feed", "--ubx", ubx.string(), "--gnss-link", rig.gnss_link.string(), "--vn100", vn100.string(),
                "--imu-link", rig.imu_link.string()},
               rig.dir / "serial_feed.log");
  const double second = logged_at(rig.daemon_log, "(pose.max_h_acc_m))", gnss_start, milliseconds(6000));
  EXPECT_GE(second, 0.0) << rig.logs();
  EXPECT_LE(second, 5.0) << rig.logs();
  EXPECT_NE(slurp(rig.daemon_log).find("withheld: no valid pose (GNSS horizontal accuracy "), std::string::npos);
  rig.stop(daemon);
}

TEST(LivePoseMessages, EveryAcceptedTrajectoryGetsANewIdThatSubscribersSee) {
  (void)corridor_run();
  const Rig rig("ids", "fixed", 3);
  Listener listener(rig.prefix);
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child lidar(TRAJROI_CLI, corridor_lidar(rig, "20"), rig.feed_log);
  const auto newest_id = [&] { return !listener.points.empty() ? listener.points.rbegin()->second.trajectory_id : -1; };
  ASSERT_TRUE(listener.wait_for([&] { return newest_id() == 0; }, seconds(10))) << rig.logs();
  // SIGHUP: the file again, under id 1.
  daemon.signal(SIGHUP);
  ASSERT_TRUE(listener.wait_for([&] { return newest_id() == 1; }, seconds(5))) << rig.logs();
  EXPECT_NE(slurp(rig.daemon_log).find("SIGHUP: trajectory 1 reloaded from " + (rig.dir / "trajectory.csv").string()),
            std::string::npos)
      << rig.logs();
  // A message whose id is not above the last: accepted under the next id, and said so.
  trajroi::trajectory_t m;
  m.id = 1;
  m.coordinates = trajroi::trajectory_t::LAT_LON;
  m.num_waypoints = 2;
  m.u = {50.13480, 50.13540};
  m.v = {14.42996, 14.42996};
  listener.publish_trajectory(m);
  ASSERT_TRUE(listener.wait_for([&] { return newest_id() == 2; }, seconds(5))) << rig.logs();
  EXPECT_NE(slurp(rig.daemon_log).find("trajectory 2 accepted from " + rig.prefix + "_TRAJECTORY: 2 waypoints"),
            std::string::npos);
  EXPECT_NE(slurp(rig.daemon_log).find("(its message said id 1, not above the last id given"), std::string::npos);
  // One above: its own id.
  m.id = 10;
  listener.publish_trajectory(m);
  ASSERT_TRUE(listener.wait_for([&] { return newest_id() == 10; }, seconds(5))) << rig.logs();
  {
    std::lock_guard<std::mutex> lock(listener.mutex);
    for (const auto& [index, points] : listener.points) {
      ASSERT_EQ(listener.rois.count(index), 1U);
      EXPECT_EQ(listener.rois.at(index).trajectory_id, points.trajectory_id) << index;
    }
  }
  ASSERT_TRUE(listener.wait_for(
      [&] { return !listener.statuses.empty() && listener.statuses.back().trajectory_id == 10; }, seconds(3)));
  rig.stop(daemon);
}

TEST(LivePoseMessages, ALocalizationFromPythonIsUsedAndItsStopReturnAndInvalidPosesAreNamed) {
  (void)corridor_run();
  const Rig rig("pyloc", "lcm", 4);
  Listener listener(rig.prefix);
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child lidar(TRAJROI_CLI, corridor_lidar(rig, "24"), rig.feed_log);
  // The planner publishes its trajectory once, as it starts: only after the daemon listens (it
  // subscribes before its first status; a sanitizer's slow start-up once lost the message).
  ASSERT_TRUE(listener.wait_for([&] { return !listener.statuses.empty(); }, seconds(20))) << rig.logs();
  // Parked on the trajectory, facing north; the planner's trajectory (id 5) first.
  {
    Child python =
        localization(rig, rig.dir / "python1.log",
                     {"--seconds", "5", "--trajectory", "50.13480,14.42995 50.13540,14.42995", "--trajectory-id", "5"});
    ASSERT_TRUE(listener.wait_for(
        [&] { return !listener.points.empty() && listener.points.rbegin()->second.trajectory_id == 5; }, seconds(10)))
        << rig.logs() << slurp(rig.dir / "python1.log");
    {
      std::lock_guard<std::mutex> lock(listener.mutex);
      const trajroi::points_t& p = listener.points.rbegin()->second;
      EXPECT_TRUE(p.pose.valid);
      EXPECT_EQ(p.pose.pose_source, "localization");
      EXPECT_EQ(p.pose.heading_source, "localization");
      EXPECT_EQ(p.pose.fix_type, trajroi::pose_t::NOT_APPLICABLE);
      EXPECT_TRUE(std::isnan(p.pose.h_acc_m));
      EXPECT_NEAR(p.pose.yaw_rad, M_PI / 2.0, 1e-6);
      const Eigen::Vector3d at = trajroi::pose::GlobalFrame::local_cartesian(kOrigin).to_global(
          trajroi::pose::Geodetic{50.13505, 14.42995, 348.0});
      EXPECT_NEAR(p.pose.position_m[0], at.x(), 1e-6);
      EXPECT_NEAR(p.pose.position_m[1], at.y(), 1e-6);
    }
    EXPECT_EQ(python.wait(seconds(10)), 0) << slurp(rig.dir / "python1.log");
  }
  // It stopped: named within 5 s, sweeps withheld in its words.
  const auto stopped = std::chrono::steady_clock::now();
  EXPECT_LOGGED_WITHIN_5S(rig, "localization: no pose_input_t on " + rig.prefix + "_POSE_INPUT for 3 s", stopped);
  EXPECT_LOGGED_WITHIN_5S(rig, "withheld: no valid pose (newest localization pose too old: ", stopped);
  EXPECT_TRUE(listener.wait_for(
      [&] {
        return !listener.statuses.empty() &&
               listener.statuses.back().state.find("localization: no pose_input_t on " + rig.prefix + "_POSE_INPUT") !=
                   std::string::npos;
      },
      seconds(3)))
      << last_status(listener).state;
  // It comes back lost: its invalid poses named; then found again.
  const auto back = std::chrono::steady_clock::now();
  {
    Child python = localization(rig, rig.dir / "python2.log", {"--seconds", "2", "--invalid"});
    EXPECT_LOGGED_WITHIN_5S(rig, "localization: poses arriving on " + rig.prefix + "_POSE_INPUT", back);
    EXPECT_LOGGED_WITHIN_5S(rig, "s on " + rig.prefix + "_POSE_INPUT marked invalid (pose_input_t.valid false", back);
    EXPECT_EQ(python.wait(seconds(10)), 0);
  }
  const std::string log = slurp(rig.daemon_log);
  EXPECT_EQ(log.find("GNSS"), std::string::npos) << "a localization is not a GNSS\n" << log;
  rig.stop(daemon);
}

TEST(LivePoseMessages, ARecordingIsAnnouncedAndReportedAndWatchEndsWithItsFigures) {
  TRAJROI_REQUIRE_DATA(pcap, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const Rig rig("record", "fixed", 5);
  const fs::path record = rig.dir / "recording";
  std::vector<std::string> args = rig.daemon_args();
  args.insert(args.end(), {"--record", record.string()});
  Listener listener(rig.prefix);
  const fs::path watch_log = rig.dir / "watch.log";
  Child watch(TRAJROI_CLI, {"watch", "--lcm-url", kTestLcmUrl, "--channel-prefix", rig.prefix, "--seconds", "60"},
              watch_log);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(args, rig.daemon_log);
  EXPECT_LOGGED_WITHIN_5S(rig, "recording every raw input into " + record.string() + " (lidar.pcap", start);
  Child feeder(TRAJROI_CLI, rig.pcap_feed(pcap, "1"), rig.feed_log);
  ASSERT_EQ(feeder.wait(seconds(20)), 0) << rig.logs();
  ASSERT_TRUE(listener.wait_for([&] { return listener.points.size() >= 2; }, seconds(5))) << rig.logs();
  std::this_thread::sleep_for(milliseconds(1200));
  EXPECT_EQ(last_status(listener).recording, record.string());
  EXPECT_NE(slurp(rig.daemon_log).find("| recording into " + record.string()), std::string::npos);
  rig.stop(daemon);
  EXPECT_GT(fs::file_size(record / "lidar.pcap"), 293U * 1206U);
  // The watch ends at the final status, with the run's latency and what --run would add.
  ASSERT_EQ(watch.wait(seconds(10)), 0) << slurp(watch_log);
  const std::string said = slurp(watch_log);
  EXPECT_NE(said.find("trajroi watch: latency over the "), std::string::npos) << said;
  EXPECT_EQ(said.find("latency p50 0.000 ms"), std::string::npos) << said;
  EXPECT_NE(said.find("not scored: --run RUN_DIR (the simulated run being replayed) adds precision, recall"),
            std::string::npos)
      << said;
}

}  // namespace
