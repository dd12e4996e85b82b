// trajroid end to end: a simulated run replayed through the daemon, heard over LCM on
// loopback, and checked against an independent decode of the same capture and against
// `trajroi filter` given the same sweep and pose.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <tuple>

#include "daemon_fixture.hpp"
#include "filter_check.hpp"
#include "trajroi/daemon/config.hpp"
#include "trajroi/roi/transform.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace {

using namespace daemon_test;
using std::chrono::milliseconds;
using std::chrono::seconds;

// Replays run at 4× real time; a slower build (ThreadSanitizer: the tsan test preset sets
// TRAJROI_TEST_REPLAY_RATE=1) gives the daemon the time a real sensor would.
const char* replay_rate() {
  const char* rate = std::getenv("TRAJROI_TEST_REPLAY_RATE");
  return rate != nullptr && *rate != '\0' ? rate : "4";
}

// A paced replay at N× real time fills each ring N times as fast: N times the default rings
// give the threads the same time to catch up as live (0.8 s for the sweeps ring, 2.7 s of
// LiDAR packets), so that a test machine busy with other tests does not drop where a robot's
// would not (CI: 5 sweeps dropped at 4× with the default 8).
std::string buffers_for_replay_rate() {
  const auto n = static_cast<std::size_t>(std::max(1.0, std::ceil(std::stod(replay_rate()))));
  const trajroi::daemon::DaemonConfig::Buffers defaults;
  return "buffers: {lidar_packets: " + std::to_string(defaults.lidar_packets * n) +
         ", serial_chunks: " + std::to_string(defaults.serial_chunks * n) +
         ", sweeps: " + std::to_string(defaults.sweeps * n) + "}\n";
}

// The run's own trajroid.yaml, plus this test's channels, pose mode and rings.
fs::path write_config(const std::string& prefix, const std::string& pose_mode, const std::string& extra = "") {
  const fs::path run = corridor_run();
  std::string text = slurp(run / "trajroid.yaml");
  text += "pose: {mode: " + pose_mode + "}\n";
  text += buffers_for_replay_rate();
  text += "lcm:\n  channels: {points: " + prefix + "_POINTS, pose: " + prefix + "_POSE, roi: " + prefix +
          "_ROI, status: " + prefix + "_STATUS, trajectory: " + prefix + "_TRAJECTORY}\n";
  text += extra;
  const fs::path file = run / (prefix + ".yaml");
  std::ofstream(file) << text;
  return file;
}

std::string unique_prefix(const char* name) {
  return "TRJTEST_" + std::to_string(::getpid()) + "_" + name;
}

// Seven complete, published sweeps spread over the run (the frame and its points_t), for the
// comparisons with trajroi filter.
std::vector<std::pair<const trajroi::vlp16::Frame*, const trajroi::points_t*>> sampled_sweeps(
    const std::vector<trajroi::vlp16::Frame>& frames, const Listener& listener) {
  std::vector<std::pair<const trajroi::vlp16::Frame*, const trajroi::points_t*>> out;
  for (std::size_t k = 5; k < frames.size(); k += frames.size() / 7) {
    const auto it = listener.points.find(static_cast<std::int64_t>(frames[k].index));
    if (it != listener.points.end() && !frames[k].partial) out.emplace_back(&frames[k], &it->second);
  }
  return out;
}

struct Replay {
  int exit_code = -1;
  std::string log;
};

// The listener must be subscribed before the replay starts; it keeps what it hears.
Replay replay(const fs::path& config, const char* rate, const std::string& lcm_url = kTestLcmUrl) {
  const fs::path err = config.parent_path() / (config.stem().string() + ".log");
  Child child({"--config", config.string(), "--replay", corridor_run().string(), "--rate", rate, "--lcm-url", lcm_url},
              err);
  Replay r;
  r.exit_code = child.wait(seconds(180));
  std::this_thread::sleep_for(milliseconds(300));  // the last datagrams on their way
  r.log = slurp(err);
  return r;
}

TEST(TrajroidEndToEnd, EverySweepArrivesAndMatchesTrajroiFilterExactlyWithOnePosePerSweep) {
  const std::string prefix = unique_prefix("EXACT");
  const fs::path config = write_config(prefix, "per_sweep");
  Listener listener(prefix);
  ASSERT_TRUE(listener.good());
  const Replay r = replay(config, replay_rate());
  ASSERT_EQ(r.exit_code, 0) << r.log;

  const auto frames = decode_capture(corridor_run() / "lidar.pcap");
  std::lock_guard<std::mutex> lock(listener.mutex);
  ASSERT_FALSE(listener.statuses.empty());
  const trajroi::status_t& last = listener.statuses.back();
  EXPECT_EQ(last.sweeps, static_cast<std::int64_t>(frames.size()));
  EXPECT_EQ(last.ring_drops, 0) << r.log;
  EXPECT_EQ(last.lost_packets, 0);
  EXPECT_EQ(last.decode_errors, 0);
  EXPECT_GT(last.sweeps_without_pose, 0) << "the GNSS outage (14–16 s) must withhold sweeps";
  EXPECT_EQ(last.sweeps_published + last.sweeps_without_pose, last.sweeps);

  // Every sweep: a pose; the valid ones also their points and ROI, in order, whole.
  ASSERT_EQ(listener.poses.size(), frames.size());
  const std::int64_t t0 = frames.front().start_time_ns;
  std::size_t withheld = 0;
  for (const auto& frame : frames) {
    const auto idx = static_cast<std::int64_t>(frame.index);
    ASSERT_EQ(listener.poses.count(idx), 1u) << idx;
    const trajroi::pose_t& pose = listener.poses.at(idx);
    if (!pose.valid) {
      ++withheld;
      EXPECT_EQ(listener.points.count(idx), 0u) << "sweep " << idx << " published without a valid pose";
      EXPECT_NE(pose.status_text, "valid");
      const double t = static_cast<double>(frame.start_time_ns - t0) * 1e-9;
      if (idx > 0) {
        EXPECT_TRUE(t > 12.0 && t < 17.0) << "sweep " << idx << " withheld at " << t << " s: " << pose.status_text;
      }
      continue;
    }
    ASSERT_EQ(listener.points.count(idx), 1u) << "sweep " << idx << " missing";
    ASSERT_EQ(listener.rois.count(idx), 1u) << "ROI of sweep " << idx << " missing";
    const trajroi::points_t& m = listener.points.at(idx);
    EXPECT_EQ(m.points_in, static_cast<std::int32_t>(frame.points.size()));
    EXPECT_EQ(m.sweep_start_ns, frame.start_time_ns);
    EXPECT_EQ(m.pose_mode, trajroi::points_t::POSE_PER_SWEEP);
    EXPECT_EQ(m.return_mode, 0x39);
  }
  EXPECT_EQ(static_cast<std::int64_t>(withheld), last.sweeps_without_pose);
  EXPECT_TRUE(std::is_sorted(listener.arrival_order.begin(), listener.arrival_order.end()));

  // Exactly what trajroi filter keeps, point for point and bit for bit, on sweeps across the run.
  const auto sampled = sampled_sweeps(frames, listener);
  EXPECT_GE(sampled.size(), 5u);
  for (const auto& [frame, message] : sampled) {
    const trajroi::points_t& m = *message;
    const std::int64_t idx = m.sweep_index;
    const auto expected =
        filter_keeps(*frame, m, listener.rois.at(idx), corridor_run(), corridor_run() / "trajectory.csv");
    const auto got = daemon_keeps(*frame, m);
    ASSERT_GT(expected.size(), 1000u);
    EXPECT_EQ(got, expected) << "sweep " << idx;
    // The coordinates, too: the published sensor pose rebuilt as documented.
    const Eigen::Isometry3d g = sensor_pose(m);
    for (std::size_t i = 0; i < got.size(); i += 97) {
      const auto& p = frame->points[got[i]];
      std::array<trajroi::roi::PointXYZI, 1> one{{{p.x, p.y, p.z, 0.0f}}};
      trajroi::roi::transform_points(g, one, one);
      EXPECT_EQ(m.x[i], one[0].x);
      EXPECT_EQ(m.y[i], one[0].y);
      EXPECT_EQ(m.z[i], one[0].z);
    }
  }
}

// Per firing, each point has its own pose. Against trajroi filter given one pose for the
// whole sweep, the one at the sweep's middle (halfway between this sweep's published start
// pose and the next's), only points within the robot's motion of a circle's edge can differ:
// at 1 m/s that is ±5 cm over 0.1 s. The kept sets, compared point for point, differ by at
// most 0.1 % of the kept points over the sampled sweeps (measured 0.07 %), 0.25 % in any one
// (a sweep whose circles' edges cross a wall: measured 0.19 %).
TEST(TrajroidEndToEnd, PerFiringMotionCompensationDiffersFromTheMidSweepPoseOnlyAtTheEdges) {
  const std::string prefix = unique_prefix("FIRING");
  const fs::path config = write_config(prefix, "per_firing");
  Listener listener(prefix);
  ASSERT_TRUE(listener.good());
  const Replay r = replay(config, replay_rate());
  ASSERT_EQ(r.exit_code, 0) << r.log;
  const auto frames = decode_capture(corridor_run() / "lidar.pcap");
  std::lock_guard<std::mutex> lock(listener.mutex);
  ASSERT_FALSE(listener.statuses.empty());
  EXPECT_EQ(listener.statuses.back().ring_drops, 0) << r.log;
  const auto sampled = sampled_sweeps(frames, listener);
  EXPECT_GE(sampled.size(), 5u);
  std::size_t differing = 0, kept = 0;
  for (const auto& [frame, message] : sampled) {
    const trajroi::points_t& m = *message;
    EXPECT_EQ(m.pose_mode, trajroi::points_t::POSE_PER_FIRING);
    const auto next = listener.points.find(m.sweep_index + 1);
    ASSERT_NE(next, listener.points.end()) << "sweep " << m.sweep_index + 1;
    const Eigen::Isometry3d start = sensor_pose(m), end = sensor_pose(next->second);
    Eigen::Isometry3d middle = Eigen::Isometry3d::Identity();
    middle.linear() =
        Eigen::Quaterniond(start.rotation()).slerp(0.5, Eigen::Quaterniond(end.rotation())).toRotationMatrix();
    middle.translation() = 0.5 * (start.translation() + end.translation());
    const auto expected = filter_keeps(*frame, m, listener.rois.at(m.sweep_index), corridor_run(),
                                       corridor_run() / "trajectory.csv", pose_argument(middle));
    ASSERT_TRUE(std::is_sorted(expected.begin(), expected.end()));
    auto got = daemon_keeps(*frame, m);
    std::sort(got.begin(), got.end());
    std::vector<std::uint32_t> symmetric;
    std::set_symmetric_difference(got.begin(), got.end(), expected.begin(), expected.end(),
                                  std::back_inserter(symmetric));
    ASSERT_GT(expected.size(), 1000u);
    EXPECT_LE(static_cast<double>(symmetric.size()) / static_cast<double>(expected.size()), 0.0025)
        << "sweep " << m.sweep_index << ": " << symmetric.size() << " of " << expected.size() << " differ";
    differing += symmetric.size();
    kept += expected.size();
  }
  EXPECT_LE(static_cast<double>(differing) / static_cast<double>(kept), 0.001) << differing << " of " << kept;
  std::printf("per firing vs the mid-sweep pose: %zu of %zu kept points differ (%.3f %%)\n", differing, kept,
              100.0 * static_cast<double>(differing) / static_cast<double>(kept));
}

// Two paced replays publish the same sweeps, bit for bit. Each run's messages are written into
// an LCM log (liblcm's file:// provider) rather than heard over multicast: a listener on a
// machine busy with other tests can miss a datagram, which would say nothing of the daemon
// (the other tests here hear the daemon over udpm).
TEST(TrajroidEndToEnd, TheSameReplayGivesTheSameOutput) {
  std::vector<std::map<std::int64_t, std::vector<float>>> runs;
  for (int run = 0; run < 2; ++run) {
    const std::string prefix = unique_prefix(run == 0 ? "SAME_A" : "SAME_B");
    const fs::path config = write_config(prefix, "per_firing");
    const fs::path log = corridor_run() / (prefix + ".lcmlog");
    const Replay r = replay(config, replay_rate(), "file://" + log.string() + "?mode=w");
    ASSERT_EQ(r.exit_code, 0) << r.log;
    std::optional<trajroi::status_t> last;
    auto& out = runs.emplace_back();
    lcm::LogFile file(log.string(), "r");
    ASSERT_TRUE(file.good()) << log;
    while (const lcm::LogEvent* e = file.readNextEvent()) {
      const auto size = static_cast<int>(e->datalen);
      if (e->channel == prefix + "_STATUS") {
        trajroi::status_t m;
        ASSERT_EQ(m.decode(e->data, 0, size), size);
        last = m;
      } else if (e->channel == prefix + "_POINTS") {
        trajroi::points_t m;
        ASSERT_EQ(m.decode(e->data, 0, size), size);
        ASSERT_EQ(out.count(m.sweep_index), 0u) << "sweep " << m.sweep_index << " published twice";
        std::vector<float>& v = out[m.sweep_index];
        v.insert(v.end(), m.x.begin(), m.x.end());
        v.insert(v.end(), m.y.begin(), m.y.end());
        v.insert(v.end(), m.z.begin(), m.z.end());
      }
    }
    fs::remove(log);
    ASSERT_TRUE(last.has_value() && last->final_status) << "no final status in " << log;
    EXPECT_EQ(last->ring_drops, 0) << "a paced replay that drops is not repeatable\n" << r.log;
    EXPECT_EQ(last->sweeps_published, static_cast<std::int64_t>(out.size()));
  }
  ASSERT_GT(runs[0].size(), 200u);
  EXPECT_EQ(runs[0].size(), runs[1].size()) << "sweeps published";
  for (const auto& [idx, a] : runs[0]) {
    const auto b = runs[1].find(idx);
    if (b == runs[1].end()) {
      ADD_FAILURE() << "sweep " << idx << " published in the first run only";
    } else if (a != b->second) {
      ADD_FAILURE() << "sweep " << idx << " differs (" << a.size() << " vs " << b->second.size() << " values)";
    }
  }
}

}  // namespace

namespace {

std::string summary_counts(const std::string& log) {
  const auto at = log.find("summary:");
  if (at == std::string::npos) return "no summary";
  const auto from = log.find("| sweeps", at);
  const auto to = log.find("| latency", at);
  return log.substr(from, to - from);
}

TEST(TrajroidEndToEnd, ARecordingReplaysToTheSameSweeps) {
  const std::string prefix = unique_prefix("RECORD");
  const fs::path config = write_config(prefix, "per_firing");
  const fs::path recorded = corridor_run().parent_path() / (prefix + "_recording");
  const fs::path log_a = corridor_run() / (prefix + "_a.log");
  const fs::path log_b = corridor_run() / (prefix + "_b.log");
  {
    Child child({"--config", config.string(), "--replay", corridor_run().string(), "--record", recorded.string(),
                 "--lcm-url", kTestLcmUrl},
                log_a);
    ASSERT_EQ(child.wait(seconds(120)), 0) << slurp(log_a);
  }
  // Serial streams: byte for byte with their receive times.
  EXPECT_EQ(slurp(recorded / "gnss.trjb"), slurp(corridor_run() / "gnss.trjb"));
  EXPECT_EQ(slurp(recorded / "imu.trjb"), slurp(corridor_run() / "imu.trjb"));
  {
    Child child({"--config", config.string(), "--replay", recorded.string(), "--lcm-url", kTestLcmUrl}, log_b);
    ASSERT_EQ(child.wait(seconds(120)), 0) << slurp(log_b);
  }
  const std::string a = summary_counts(slurp(log_a));
  EXPECT_NE(slurp(log_a).find("| ring drops 0 |"), std::string::npos) << slurp(log_a);
  EXPECT_EQ(summary_counts(slurp(log_b)), a);
  fs::remove_all(recorded);
}

// SIGTERM 5.05 s into a real-time replay that records: half a sweep is in progress and the
// recorder is writing. The daemon exits 0 within a second; the recording holds every input
// it processed, whole: the serial recordings are exact prefixes of the originals, the pcap
// reads to its end without a torn record, and replaying it gives the same sweeps.
TEST(TrajroidEndToEnd, SigtermInTheMiddleOfASweepAndARecordingLeavesACompleteRecording) {
  const std::string prefix = unique_prefix("SIGTERM_RECORD");
  const fs::path config = write_config(prefix, "per_firing");
  const fs::path recorded = corridor_run().parent_path() / (prefix + "_recording");
  const fs::path log_a = corridor_run() / (prefix + "_a.log");
  const fs::path log_b = corridor_run() / (prefix + "_b.log");
  {
    Child child({"--config", config.string(), "--replay", corridor_run().string(), "--rate", "1", "--record",
                 recorded.string(), "--lcm-url", kTestLcmUrl},
                log_a);
    std::this_thread::sleep_for(milliseconds(5050));
    const auto sent = std::chrono::steady_clock::now();
    child.signal(SIGTERM);
    ASSERT_EQ(child.wait(seconds(5)), 0) << slurp(log_a);
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
    EXPECT_LT(took, 1.0) << "SIGTERM to exit";
  }
  for (const char* name : {"gnss.trjb", "imu.trjb"}) {
    const std::string part = slurp(recorded / name);
    const std::string whole = slurp(corridor_run() / name);
    EXPECT_GT(part.size(), 1000u) << name;
    EXPECT_LT(part.size(), whole.size()) << name;
    EXPECT_EQ(part, whole.substr(0, part.size())) << name << ": not a prefix of the original";
  }
  {
    trajroi::vlp16::PcapSource source(recorded / "lidar.pcap");
    trajroi::vlp16::Datagram d;
    std::size_t datagrams = 0;
    trajroi::vlp16::PacketSource::Next r;
    while ((r = source.next(d)) == trajroi::vlp16::PacketSource::Next::kDatagram)
      ++datagrams;
    EXPECT_EQ(r, trajroi::vlp16::PacketSource::Next::kEnd) << source.error();
    EXPECT_EQ(source.skipped_records(), 0u);
    EXPECT_GT(datagrams, 3000u) << "about 5 s of dual-return packets";
  }
  {
    Child child({"--config", config.string(), "--replay", recorded.string(), "--lcm-url", kTestLcmUrl}, log_b);
    ASSERT_EQ(child.wait(seconds(120)), 0) << slurp(log_b);
  }
  EXPECT_EQ(summary_counts(slurp(log_b)), summary_counts(slurp(log_a))) << slurp(log_a) << slurp(log_b);
  fs::remove_all(recorded);
}

}  // namespace
