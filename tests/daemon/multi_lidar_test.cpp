// Two LiDARs on one robot, live: two real captures sent at once over UDP from two loopback
// addresses (127.0.0.2: the MRPT VLP-16, strongest return; 127.0.0.3: nebula's VLP-16, dual
// return), to one port (told apart by sender) or to two ports, the two sensors mounted
// differently. Each merged points_t must hold, for each sensor, exactly what `trajroi filter`
// keeps of one of that capture's sweeps placed with the sensor's pose (the published robot pose
// times its mounting) against the published ROI, and each merged raw_points every third point
// of those sweeps, by index, placed alike, marked with its sensor, its times moved as the kept
// points' were. The rear sensor then stops while the front one goes on: the rear is named
// silent, and the front's sweeps are still published, alone.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <thread>

#include "daemon_fixture.hpp"
#include "filter_check.hpp"
#include "real_rig.hpp"
#include "test_data.hpp"
#include "trajroi/pipeline/sweep.hpp"

namespace {

using namespace daemon_test;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr const char* kDual = "velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap";

struct Sensor {
  const char* name;
  const char* address;
  int data_port;
  Eigen::Isometry3d mounting;
  std::vector<trajroi::vlp16::Frame> frames;
};

Eigen::Isometry3d mounting(double x, double y, double z, double yaw_deg) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translation() = Eigen::Vector3d(x, y, z);
  m.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return m;
}

// The sensor's pose as the daemon computes it: the published robot pose times the mounting.
trajroi::pipeline::PublishedPose sensor_pose(const trajroi::points_t& m, const Eigen::Isometry3d& robot_from_lidar) {
  trajroi::pipeline::PublishedPose robot;
  robot.position_m = Eigen::Vector3d(m.pose.position_m[0], m.pose.position_m[1], m.pose.position_m[2]);
  robot.orientation =
      Eigen::Quaterniond(m.pose.orientation[0], m.pose.orientation[1], m.pose.orientation[2], m.pose.orientation[3]);
  return trajroi::pipeline::PublishedPose::from(robot.isometry() * robot_from_lidar);
}

// The capture's sweep whose points sensor `index` has in `m`, and by how much their times
// moved (they count from the merged sweep's start).
struct Match {
  const trajroi::vlp16::Frame* frame = nullptr;
  std::int64_t shift_ns = 0;
};

// The points of sensor `index` in `m` (a points_t on the points or the raw_points channel).
std::vector<std::size_t> points_of(const trajroi::points_t& m, std::uint8_t index) {
  std::vector<std::size_t> mine;
  for (std::size_t k = 0; k < static_cast<std::size_t>(m.num_points); ++k)
    if (m.sensor[k] == index) mine.push_back(k);
  return mine;
}

// Whether point k of `m` is the frame's point `p` placed with `pose`, its time moved by `shift_ns`.
bool is_placed(const trajroi::points_t& m, std::size_t k, const trajroi::vlp16::Point& p,
               const trajroi::pipeline::PublishedPose& pose, std::int64_t shift_ns) {
  if (m.time_offset_ns[k] - shift_ns != static_cast<std::int64_t>(p.time_offset_ns) || m.ring[k] != p.ring ||
      m.return_type[k] != static_cast<std::uint8_t>(p.return_type))
    return false;
  // Placed by this sensor's mounting: within float rounding of the pose times the point.
  const Eigen::Vector3d g = pose.isometry() * Eigen::Vector3f(p.x, p.y, p.z).cast<double>();
  return (g - Eigen::Vector3f(m.x[k], m.y[k], m.z[k]).cast<double>()).norm() < 1e-3;
}

// The sweep of which the points of sensor `index` in `m` are exactly what trajroi filter keeps
// (placed with the sensor's pose, against the published ROI); none when no sweep matches.
Match matching_sweep(const trajroi::points_t& m, const trajroi::roi_t& roi, std::uint8_t index, const Sensor& sensor,
                     const Rig& rig) {
  const std::vector<std::size_t> mine = points_of(m, index);
  if (mine.empty()) return {};
  const auto pose = sensor_pose(m, sensor.mounting);
  for (const auto& frame : sensor.frames) {
    if (frame.partial) continue;
    const auto expected = filter_keeps(frame, m, roi, rig.dir, rig.trajectory_xy,
                                       pose_argument(pose.position_m, pose.orientation.w(), pose.orientation.x(),
                                                     pose.orientation.y(), pose.orientation.z()));
    if (expected.size() != mine.size()) continue;
    const std::int64_t shift =
        m.time_offset_ns[mine[0]] - static_cast<std::int64_t>(frame.points[expected[0]].time_offset_ns);
    bool same = true;
    for (std::size_t j = 0; j < mine.size() && same; ++j)
      same = is_placed(m, mine[j], frame.points[expected[j]], pose, shift);
    if (same) return {&frame, shift};
  }
  return {};
}

// Whether the raw points (outputs.raw_points) of sensor `index` in `raw` are every
// `decimation`th point of the matched sweep, by index, placed with the sensor's pose, their
// times moved as the kept points' were.
bool raw_matches(const trajroi::points_t& raw, std::uint8_t index, const Sensor& sensor, const Match& match,
                 std::size_t decimation) {
  const std::vector<std::size_t> mine = points_of(raw, index);
  const std::vector<trajroi::vlp16::Point>& points = match.frame->points;
  if (mine.size() != (points.size() + decimation - 1) / decimation) return false;
  const auto pose = sensor_pose(raw, sensor.mounting);
  for (std::size_t j = 0; j < mine.size(); ++j)
    if (!is_placed(raw, mine[j], points[j * decimation], pose, match.shift_ns)) return false;
  return true;
}

// Seconds into the day of the first log line holding `text` (its "YYYY-MM-DD HH:MM:SS.mmm").
double logged_at(const std::string& log, const std::string& text) {
  const std::size_t at = log.find(text);
  if (at == std::string::npos) return 1e9;
  const std::size_t line = log.rfind('\n', at) == std::string::npos ? 0 : log.rfind('\n', at) + 1;
  int h = 0, m = 0;
  double s = 0.0;
  if (std::sscanf(log.c_str() + line + 11, "%d:%d:%lf", &h, &m, &s) != 3) return 1e9;
  return h * 3600.0 + m * 60.0 + s;
}

// Seconds into the day `file` was last written, in local time as the log's stamps are.
double modified_at(const fs::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return 0.0;
  std::tm t{};
  localtime_r(&st.st_mtim.tv_sec, &t);
  return t.tm_hour * 3600.0 + t.tm_min * 60.0 + t.tm_sec + static_cast<double>(st.st_mtim.tv_nsec) * 1e-9;
}

// The capture's data packets played `plays` times over as one sensor running that much longer:
// each play's record times and VLP-16 clock (top-of-hour µs) moved on by the capture's length
// (a sensor never repeats its clock: the same bytes again would be late packets). Position
// packets in the first play only. A classic little-endian Ethernet pcap, as the MRPT one is.
fs::path played_longer(const fs::path& pcap, int plays, const fs::path& out) {
  const std::string in = slurp(pcap);
  const auto u32 = [](const std::string& b, std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, b.data() + at, 4);
    return v;
  };
  constexpr std::size_t kPayload = 42, kToh = kPayload + 1200;  // Ethernet + IPv4 + UDP; timestamp
  std::vector<std::size_t> records;
  for (std::size_t at = 24; at + 16 <= in.size(); at += 16 + u32(in, at + 8))
    records.push_back(at);
  const auto is_data = [&](std::size_t at) { return u32(in, at + 8) == kPayload + 1206; };
  std::uint32_t first = 0, last = 0;
  for (const std::size_t at : records) {
    if (!is_data(at)) continue;
    if (first == 0) first = u32(in, at + 16 + kToh);
    last = u32(in, at + 16 + kToh);
  }
  const std::uint32_t length_us = last - first + 1327;  // one packet period after the last
  std::string o = in.substr(0, 24);
  for (int play = 0; play < plays; ++play) {
    for (const std::size_t at : records) {
      if (play > 0 && !is_data(at)) continue;
      std::string r = in.substr(at, 16 + u32(in, at + 8));
      const std::uint64_t shift = static_cast<std::uint64_t>(play) * length_us;
      const std::uint64_t t_us = u32(r, 0) * 1'000'000ULL + u32(r, 4) + shift;
      const auto sec = static_cast<std::uint32_t>(t_us / 1'000'000),
                 usec = static_cast<std::uint32_t>(t_us % 1'000'000);
      std::memcpy(r.data(), &sec, 4);
      std::memcpy(r.data() + 4, &usec, 4);
      if (is_data(at)) {
        const auto toh = static_cast<std::uint32_t>((u32(r, 16 + kToh) + shift) % 3'600'000'000ULL);
        std::memcpy(r.data() + 16 + kToh, &toh, 4);
      }
      o += r;
    }
  }
  std::ofstream(out, std::ios::binary) << o;
  return out;
}

class MultiLidar : public testing::TestWithParam<bool> {};

TEST_P(MultiLidar, TwoLiveSendersMergeAsTrajroiFilterKeepsEachAndASilentOneIsNamed) {
  TRAJROI_REQUIRE_DATA(strongest, kPcap);
  TRAJROI_REQUIRE_DATA(dual, kDual);
  const bool one_port = GetParam();
  const Rig rig(one_port ? "multi_one_port" : "multi_two_ports", "fixed", one_port ? 16 : 17);
  // The front sensor runs four times the capture's length, the rear once: it stops mid-run.
  const fs::path longer = played_longer(strongest, 4, rig.dir / "front.pcap");
  Sensor front{"front", "127.0.0.2", rig.data_port, mounting(0.4, 0.1, 0.8, 10.0), decode_capture(longer)};
  Sensor rear{"rear", "127.0.0.3", one_port ? rig.data_port : rig.data_port + 2, mounting(-0.4, -0.1, 0.7, 190.0),
              decode_capture(dual)};
  // lidars: in place of the rig's lidar: (its ports, ranges), the two sensors.
  std::string text = slurp(rig.config);
  const std::size_t from = text.find("lidar:\n"), to = text.find("pose:\n");
  std::string lidars = "lidars:\n";
  for (const Sensor* s : {&front, &rear}) {
    char entry[512];
    const Eigen::Vector3d t = s->mounting.translation();
    const double yaw = std::atan2(s->mounting.linear()(1, 0), s->mounting.linear()(0, 0)) * 180.0 / M_PI;
    std::snprintf(entry, sizeof entry,
                  "  - name: %s\n    sensor_address: %s\n    data_port: %d\n    position_port: %d\n"
                  "    mounting: {xyz: [%.17g, %.17g, %.17g], yaw_deg: %.17g}\n    min_range_m: 0.5\n",
                  s->name, s->address, s->data_port, s->data_port + 1, t.x(), t.y(), t.z(), yaw);
    lidars += entry;
  }
  text.replace(from, to - from, lidars + "lidar_merge: {max_wait_s: 0.15, silent_s: 0.5}\n");
  std::ofstream(rig.config) << text;
  rig.add_under("roi", "  circle_diameter_m: 3\n  look_ahead_m: 10\n");
  // The decoded points before the ROI too, one in three: each tells its sensor.
  constexpr std::size_t kDecimation = 3;
  rig.add_under("outputs", "  raw_points: true\n  raw_points_decimation: " + std::to_string(kDecimation) + "\n");
  text = slurp(rig.config);
  const std::string last_channel = rig.prefix + "_POSE_INPUT}";
  text.replace(text.find(last_channel), last_channel.size(),
               rig.prefix + "_POSE_INPUT, raw_points: " + rig.prefix + "_RAW_POINTS}");
  std::ofstream(rig.config) << text;

  Listener listener(rig.prefix);
  ASSERT_TRUE(listener.good());
  Listener raw_listener(rig.prefix + "_RAW");  // its "points": <prefix>_RAW_POINTS
  ASSERT_TRUE(raw_listener.good());
  // Recorded as it runs: the replay below must tell the sensors apart the same way.
  const fs::path recording = rig.dir / "recording";
  std::vector<std::string> args = rig.daemon_args();
  args.insert(args.end(), {"--record", recording.string()});
  Child daemon(args, rig.daemon_log);
  ASSERT_TRUE(wait_until_running(rig.daemon_log)) << rig.logs();
  // The rear's copies from 127.0.0.4, a sender that is no sensor's: dropped, counted.
  const auto feed = [&](const Sensor& s, const fs::path& pcap, const std::string& after, const std::string& log) {
    std::vector<std::string> a{"feed",
                               "--pcap",
                               pcap.string(),
                               "--from",
                               s.address,
                               "--data-port",
                               std::to_string(s.data_port),
                               "--position-port",
                               std::to_string(s.data_port + 1),
                               "--lidar-after",
                               after};
    if (&s == &rear) a.insert(a.end(), {"--foreign-from", "127.0.0.4", "--foreign-every", "10"});
    return std::make_unique<Child>(TRAJROI_CLI, a, rig.dir / log);
  };
  // Both at once: the front for 1.55 s, the rear for 0.40 s.
  {
    const auto front_feed = feed(front, longer, "0", "feed_front.log");
    const auto rear_feed = feed(rear, dual, "0", "feed_rear.log");
    ASSERT_EQ(rear_feed->wait(seconds(20)), 0) << rig.logs();
    ASSERT_EQ(front_feed->wait(seconds(20)), 0) << rig.logs();
  }
  std::this_thread::sleep_for(milliseconds(1500));
  rig.stop(daemon);

  const std::string log = slurp(rig.daemon_log);
  const std::string silent = "lidar: rear (127.0.0.3 → UDP " + std::to_string(rear.data_port) + ") silent";
  EXPECT_NE(log.find(silent), std::string::npos) << log;
  const std::lock_guard<std::mutex> lock(listener.mutex);
  const std::lock_guard<std::mutex> raw_lock(raw_listener.mutex);
  std::size_t both = 0, matched_front = 0, matched_rear = 0, front_alone = 0, raw_front = 0, raw_rear = 0;
  std::size_t with_missing = 0;
  for (const auto& [index, m] : listener.points) {
    with_missing += m.missing.empty() ? 0U : 1U;
    ASSERT_EQ(m.num_sensors, 2) << "sweep " << index;
    EXPECT_EQ(m.sensor_names, (std::vector<std::string>{"front", "rear"}));
    EXPECT_TRUE(m.pose.valid);
    bool has[2] = {false, false};
    for (const std::uint8_t s : m.sensor) {
      ASSERT_LT(s, 2) << "sweep " << index;
      has[s] = true;
    }
    const auto roi = listener.rois.find(index);
    ASSERT_NE(roi, listener.rois.end());
    if (has[0] && has[1]) {
      ++both;
      const Match f = matching_sweep(m, roi->second, 0, front, rig);
      const Match r = matching_sweep(m, roi->second, 1, rear, rig);
      matched_front += f.frame != nullptr ? 1U : 0U;
      matched_rear += r.frame != nullptr ? 1U : 0U;
      const auto raw = raw_listener.points.find(index);
      if (raw == raw_listener.points.end()) continue;
      EXPECT_EQ(raw->second.num_sensors, 2) << "sweep " << index;
      EXPECT_EQ(raw->second.sensor_names, (std::vector<std::string>{"front", "rear"}));
      raw_front += f.frame != nullptr && raw_matches(raw->second, 0, front, f, kDecimation) ? 1U : 0U;
      raw_rear += r.frame != nullptr && raw_matches(raw->second, 1, rear, r, kDecimation) ? 1U : 0U;
    } else if (has[0] && !has[1] && m.missing.empty()) {
      // After the rear fell silent: not waited for, not missing.
      front_alone += matching_sweep(m, roi->second, 0, front, rig).frame != nullptr ? 1U : 0U;
    }
  }
  std::printf(
      "[ multi lidar ] %s: %zu sweeps published, %zu with both sensors (front as trajroi filter keeps in %zu, "
      "rear in %zu; their raw points as decoded, one in %zu, in %zu and %zu), %zu of the front alone after the "
      "rear fell silent\n",
      one_port ? "one port" : "two ports", listener.points.size(), both, matched_front, matched_rear, kDecimation,
      raw_front, raw_rear, front_alone);
  EXPECT_GE(both, 2U) << log;
  EXPECT_GE(matched_front, 2U) << log;
  EXPECT_GE(matched_rear, 2U) << log;
  EXPECT_GE(raw_front, 2U) << log;
  EXPECT_GE(raw_rear, 2U) << log;
  EXPECT_GE(front_alone, 3U) << log;
  // Named within 1 s of its last datagram (the feed's end, by its log's time).
  const double said_s = logged_at(log, silent), ended_s = modified_at(rig.dir / "feed_rear.log");
  std::printf("[ multi lidar ] the rear named silent %.3f s after its last datagram\n", said_s - ended_s);
  EXPECT_LT(said_s - ended_s, 1.0) << log;
  ASSERT_FALSE(listener.statuses.empty());
  EXPECT_EQ(listener.statuses.back().decode_errors, 0);
  EXPECT_GE(counter(listener.statuses.back(), "lidar.rejected_source"), 5);
  // The merged sweeps counted as they went out: each message received, and those that went
  // out without a sensor waited for (points_t.missing).
  EXPECT_EQ(counter(listener.statuses.back(), "lidar_merge.published"),
            static_cast<std::int64_t>(listener.points.size()));
  EXPECT_EQ(counter(listener.statuses.back(), "lidar_merge.incomplete"), static_cast<std::int64_t>(with_missing));
  EXPECT_NE(log.find("merged sweeps published " + std::to_string(listener.points.size()) + " (" +
                     std::to_string(with_missing) + " without a sensor waited for)"),
            std::string::npos)
      << log;
  // The state names it too.
  bool stated = false;
  for (const trajroi::status_t& st : listener.statuses)
    stated = stated || st.state.find("LiDAR rear (127.0.0.3 → UDP " + std::to_string(rear.data_port) + "): silent") !=
                           std::string::npos;
  EXPECT_TRUE(stated) << log;

  // The recording replayed as fast as possible: the same merged sweeps, each sensor's points
  // where the live run had them (the recorded senders and ports route them). Such a replay sends
  // its sweeps within tens of milliseconds, some megabytes: on a loaded machine (ctest -j) this
  // test's own listener may miss some (UDP, its socket's buffer full) though trajroid sent them
  // all. Its summary says how many it sent; a replay whose sweeps did not all arrive is run
  // again, on channels of its own, at most three times.
  std::size_t same = 0, received = 0;
  std::string replay_log;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    const std::string prefix = rig.prefix + "_R" + std::to_string(attempt);
    Listener replayed(prefix);
    ASSERT_TRUE(replayed.good());
    std::string replay_config = slurp(rig.config);
    for (const char* channel : {"_POINTS", "_POSE", "_ROI", "_STATUS", "_TRAJECTORY", "_POSE_INPUT", "_RAW_POINTS"}) {
      const std::string name = rig.prefix + channel;
      replay_config.replace(replay_config.find(name), name.size(), prefix + channel);
    }
    std::ofstream(rig.dir / "replay.yaml") << replay_config;
    Child replay(
        {"--config", (rig.dir / "replay.yaml").string(), "--replay", recording.string(), "--lcm-url", kTestLcmUrl},
        rig.dir / "replay.log");
    ASSERT_EQ(replay.wait(seconds(30)), 0) << slurp(rig.dir / "replay.log");
    std::this_thread::sleep_for(milliseconds(300));
    replay_log = slurp(rig.dir / "replay.log");
    const std::lock_guard<std::mutex> replay_lock(replayed.mutex);
    received = replayed.points.size();
    same = 0;
    for (const auto& [index, m] : listener.points) {
      const auto it = replayed.points.find(index);
      if (it == replayed.points.end()) continue;
      same += it->second.sensor == m.sensor && it->second.x == m.x && it->second.missing == m.missing ? 1U : 0U;
    }
    std::printf("[ multi lidar ] replayed (attempt %d): %zu sweeps received, %zu equal to the live run's\n", attempt,
                received, same);
    if (replay_log.find("merged sweeps published " + std::to_string(received) + " (") != std::string::npos) break;
  }
  // As many merged sweeps as live, and each as live. (Two sockets: two senders' datagrams
  // within a millisecond may be taken live in another order than their recorded times at a
  // window's edge.)
  EXPECT_NE(replay_log.find("merged sweeps published " + std::to_string(listener.points.size()) + " ("),
            std::string::npos)
      << replay_log;
  EXPECT_GE(same + 2, listener.points.size()) << replay_log;
}

INSTANTIATE_TEST_SUITE_P(Ports, MultiLidar, testing::Values(true, false),
                         [](const testing::TestParamInfo<bool>& p) { return p.param ? "OnePort" : "TwoPorts"; });

}  // namespace
