// trajroid live under faults: real processes, pseudo-terminals and loopback sockets, no mocks.
// `trajroi feed` plays a simulated run into the daemon as its sensors would (UDP datagrams
// to 127.0.0.1, GNSS and IMU through pseudo-terminals) and injects the fault; the test
// listens over LCM and reads the daemon's counters. Without a fault, `trajroi watch` scores
// the live daemon's sweeps against the run's truth (TrajroidLive).
#include <algorithm>
#include <cstdlib>

#include "daemon_fixture.hpp"

namespace {

using namespace daemon_test;
using std::chrono::milliseconds;
using std::chrono::seconds;

// The scenario with a degraded then lost GNSS fix (tests/daemon/outage.yaml).
const fs::path& outage_run() {
  static const fs::path dir = simulate(TRAJROI_OUTAGE_SCENARIO, "outage");
  return dir;
}

bool under_sanitizer() {
  return std::getenv("TRAJROI_SANITIZER") != nullptr;
}

// One live test: its own channels, UDP ports and device links.
void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("'" + from + "' not in the run's configuration");
  text.replace(at, from.size(), to);
}

struct LiveRig {
  std::string prefix;
  fs::path dir;  // holds the config, the device links and the logs
  int data_port = 0;
  fs::path config, gnss_link, imu_link, daemon_log, feed_log;

  LiveRig(const fs::path& run, const std::string& name, int port_offset, const std::string& extra_lidar = "") {
    const int pid = ::getpid();
    prefix = "TRJTEST_" + std::to_string(pid) + "_" + name;
    dir = fs::temp_directory_path() / ("trajroid_live_" + name + "_" + std::to_string(pid));
    fs::create_directories(dir);
    // Ports unlikely to be taken by another test program running beside this one.
    data_port = 20000 + (pid % 4000) * 8 + port_offset * 2;
    gnss_link = dir / "gnss";
    imu_link = dir / "imu";
    daemon_log = dir / "trajroid.log";
    feed_log = dir / "feed.log";
    std::string text = slurp(run / "trajroid.yaml");
    // The simulated run's configuration, pointed at the live sources: the run's relative
    // trajectory path is made absolute since this file lives elsewhere.
    replace_once(text, "file: trajectory.csv", "file: " + (run / "trajectory.csv").string());
    replace_once(text, "\nlidar:\n",
                 "\nlidar:\n  data_port: " + std::to_string(data_port) +
                     "\n  position_port: " + std::to_string(data_port + 1) + "\n" + extra_lidar);
    replace_once(text, "\ngnss:\n", "\ngnss:\n  device: " + gnss_link.string() + "\n");
    replace_once(text, "\nimu:\n", "\nimu:\n  device: " + imu_link.string() + "\n");
    text += "lcm:\n  channels: {points: " + prefix + "_POINTS, pose: " + prefix + "_POSE, roi: " + prefix +
            "_ROI, status: " + prefix + "_STATUS, trajectory: " + prefix + "_TRAJECTORY}\n";
    config = dir / "trajroid.yaml";
    std::ofstream(config) << text;
  }
  ~LiveRig() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  [[nodiscard]] std::vector<std::string> feed_args(const fs::path& run, std::vector<std::string> extra) const {
    std::vector<std::string> a{"feed",
                               run.string(),
                               "--data-port",
                               std::to_string(data_port),
                               "--position-port",
                               std::to_string(data_port + 1),
                               "--gnss-link",
                               gnss_link.string(),
                               "--imu-link",
                               imu_link.string(),
                               "--linger",
                               "5"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  [[nodiscard]] std::string logs() const {
    return "--- trajroid log ---\n" + slurp(daemon_log) + "--- feed log ---\n" + slurp(feed_log);
  }
};

// Waits until `text` shows in the log `file`.
bool wait_for_text(const fs::path& file, const std::string& text, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (slurp(file).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(milliseconds(50));
  }
  return false;
}

// Waits for the feeder to print its closing line (it then lingers, devices still there).
bool wait_for_feed_done(const LiveRig& rig, std::chrono::milliseconds timeout) {
  return wait_for_text(rig.feed_log, "feed: done:", timeout);
}

// The number right after `prefix` (its first occurrence at or after `from`) in a log.
double number_after(const std::string& log, const std::string& prefix, std::size_t from = 0) {
  const auto at = log.find(prefix, from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "no '" << prefix << "' in the log:\n" << log;
    return -1.0;
  }
  return std::strtod(log.c_str() + at + prefix.size(), nullptr);
}
std::int64_t count_after(const std::string& log, const std::string& prefix, std::size_t from = 0) {
  return static_cast<std::int64_t>(number_after(log, prefix, from));
}

// Once the feeder has printed its closing line (it lingers, the devices still there): lets the
// last sweep and status out, then stops the daemon, which must exit 0.
testing::AssertionResult stop_after_feed(const LiveRig& rig, Child& daemon, std::chrono::milliseconds timeout) {
  if (!wait_for_feed_done(rig, timeout)) return testing::AssertionFailure() << "the feed did not end\n" << rig.logs();
  std::this_thread::sleep_for(milliseconds(1500));
  daemon.signal(SIGTERM);
  const int code = daemon.wait(seconds(5));
  if (code != 0) return testing::AssertionFailure() << "trajroid exited with " << code << "\n" << rig.logs();
  return testing::AssertionSuccess();
}

long rss_kb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

// Start time of each sweep the daemon reported (pose_t, published valid or not) relative to
// sweep 0: the data time, as the simulated firings start at 0.
std::map<std::int64_t, double> sweep_times(Listener& listener) {
  std::lock_guard<std::mutex> lock(listener.mutex);
  std::map<std::int64_t, double> t;
  if (listener.poses.empty()) return t;
  const std::int64_t t0 = listener.poses.begin()->second.t_ns;
  for (const auto& [idx, p] : listener.poses)
    t[idx] = static_cast<double>(p.t_ns - t0) * 1e-9;
  return t;
}

// A serial device unplugged in the middle of a frame and plugged back: the daemon reopens it
// within a second of its return, the pose comes back, each disconnect is counted.
TEST(TrajroidFaults, SerialDevicesUnpluggedMidFrameAreReopenedWithinASecond) {
  const fs::path& run = corridor_run();
  LiveRig rig(run, "HANGUP", 0);
  Listener listener(rig.prefix);
  ASSERT_TRUE(listener.good());
  Child daemon({"--config", rig.config.string(), "--lcm-url", kTestLcmUrl}, rig.daemon_log);
  Child feed(TRAJROI_CLI, rig.feed_args(run, {"--hangup", "gnss@5+2", "--hangup", "imu@9+1"}), rig.feed_log);
  ASSERT_TRUE(stop_after_feed(rig, daemon, seconds(60)));

  const std::string log = slurp(rig.feed_log);
  for (const char* stream : {"gnss", "imu"}) {
    const auto vanished = log.find(std::string("feed: ") + stream + " device vanished at ");
    ASSERT_NE(vanished, std::string::npos) << log;
    EXPECT_GT(count_after(log, "s of data, ", vanished), 0) << "unplugged mid-frame";
    const double reopen_s = number_after(log, std::string("feed: ") + stream + " reopened by the reader ");
    EXPECT_LE(reopen_s, 1.0) << stream;
  }

  const auto times = sweep_times(listener);
  std::lock_guard<std::mutex> lock(listener.mutex);
  ASSERT_FALSE(listener.statuses.empty());
  const trajroi::status_t& last = listener.statuses.back();
  EXPECT_TRUE(last.final_status);
  EXPECT_EQ(counter(last, "serial.disconnects"), 2) << rig.logs();
  // Pose lost while the GNSS was away (5 … 7 s) and the IMU (9 … 10 s), back after.
  std::size_t during_gnss = 0, withheld_gnss = 0, after = 0, published_after = 0;
  for (const auto& [idx, t] : times) {
    const bool published = listener.points.count(idx) == 1;
    if (t > 5.4 && t < 6.9) {
      ++during_gnss;
      withheld_gnss += published ? 0 : 1;
    }
    if (t > 10.6 && t < 13.5) {  // before the scenario's own GNSS outage at 14 s
      ++after;
      published_after += published ? 1 : 0;
    }
  }
  EXPECT_GT(during_gnss, 10U);
  EXPECT_EQ(withheld_gnss, during_gnss);
  EXPECT_GT(after, 20U);
  EXPECT_EQ(published_after, after) << rig.logs();
}

// GNSS degrades (RTK float) and is then lost for 10 s: sweeps keep coming while the fix is
// degraded but inside the gate, stop within the pose timeout of the loss, resume after it.
TEST(TrajroidFaults, GnssDegradedThenLostForTenSecondsStopsAndResumesFilteredSweeps) {
  const fs::path& run = outage_run();
  LiveRig rig(run, "OUTAGE", 1);
  Listener listener(rig.prefix);
  ASSERT_TRUE(listener.good());
  Child daemon({"--config", rig.config.string(), "--lcm-url", kTestLcmUrl}, rig.daemon_log);
  Child feed(TRAJROI_CLI, rig.feed_args(run, {}), rig.feed_log);
  ASSERT_TRUE(stop_after_feed(rig, daemon, seconds(60)));

  // The configured pose timeout (pose.max_extrapolation_s) and one sweep (0.1 s) to notice.
  constexpr double kTimeout = 0.25, kSweep = 0.1, kLossFrom = 8.0, kLossTo = 18.0;
  const auto times = sweep_times(listener);
  std::lock_guard<std::mutex> lock(listener.mutex);
  ASSERT_GT(times.size(), 250U);
  double last_before = -1.0, first_after = 1e9;
  std::size_t degraded = 0;
  for (const auto& [idx, t] : times) {
    const bool published = listener.points.count(idx) == 1;
    const trajroi::pose_t& pose = listener.poses.at(idx);
    if (t > 3.0 && t < kLossFrom - kSweep) {
      EXPECT_TRUE(published) << "sweep " << idx << " at " << t << " s: " << pose.status_text;
      if (t > 5.5 && t < 7.5 && pose.h_acc_m > 0.2) ++degraded;  // RTK float, still inside the gate
    }
    if (t >= kLossFrom + kTimeout + kSweep && t < kLossTo) {
      EXPECT_FALSE(published) << "sweep " << idx << " at " << t << " s";
      EXPECT_FALSE(pose.valid);
    }
    if (t > kLossTo + 0.5 && t < static_cast<double>(times.size()) * kSweep - 1.0) {
      EXPECT_TRUE(published) << "sweep " << idx << " at " << t << " s: " << pose.status_text;
    }
    if (published && t < kLossTo) last_before = std::max(last_before, t);
    if (published && t > kLossFrom + 1.0) first_after = std::min(first_after, t);
  }
  EXPECT_GT(degraded, 10U) << "the degraded fix shows in the published poses";
  EXPECT_LE(last_before, kLossFrom + kTimeout) << "filtered sweeps stop within the pose timeout";
  EXPECT_LE(first_after, kLossTo + 0.5) << "and resume when the fix is back";
  EXPECT_EQ(listener.statuses.back().ring_drops, 0);
}

// 20× the data packet rate for 10 s, half of it malformed, plus a sender that is not the
// sensor: every datagram is accounted for, memory stays flat, sweeps keep coming through the
// flood and are whole again after it.
TEST(TrajroidFaults, UdpFloodWithMalformedPacketsIsCountedBoundedAndRecoveredFrom) {
  const fs::path& run = corridor_run();
  LiveRig rig(run, "FLOOD", 2, "  sensor_address: 127.0.0.1\n");
  Listener listener(rig.prefix);
  ASSERT_TRUE(listener.good());
  Child daemon({"--config", rig.config.string(), "--lcm-url", kTestLcmUrl}, rig.daemon_log);
  Child feed(TRAJROI_CLI,
             rig.feed_args(run, {"--flood-at", "5", "--flood-for", "10", "--flood-factor", "20", "--foreign-from",
                                 "127.0.0.2", "--foreign-every", "10"}),
             rig.feed_log);
  // Resident memory before the flood, once sweeps are published (3.5 … 4.8 s of data; the
  // pose is valid from 2.5 s), and from the flood's start on.
  long before_kb = 0, peak_kb = 0;
  const auto until = std::chrono::steady_clock::now() + seconds(60);
  while (std::chrono::steady_clock::now() < until && slurp(rig.feed_log).find("feed: done:") == std::string::npos) {
    std::int64_t newest = -1;
    {
      std::lock_guard<std::mutex> lock(listener.mutex);
      if (!listener.poses.empty()) newest = listener.poses.rbegin()->first;
    }
    const long kb = rss_kb(daemon.pid());
    if (newest >= 35 && newest < 48) before_kb = std::max(before_kb, kb);
    if (newest >= 50) peak_kb = std::max(peak_kb, kb);
    std::this_thread::sleep_for(milliseconds(100));
  }
  ASSERT_TRUE(stop_after_feed(rig, daemon, seconds(1)));

  const std::string log = slurp(rig.feed_log);
  // "UDP sent N (D data, F flood of which M malformed) from 127.0.0.1, X from 127.0.0.2"
  const std::int64_t sent = count_after(log, "UDP sent ");
  const std::int64_t data = count_after(log, "(", log.find("UDP sent "));
  const std::int64_t flood = count_after(log, " data, ");
  const std::int64_t malformed = count_after(log, "of which ");
  const std::int64_t foreign = count_after(log, "from 127.0.0.1, ");
  EXPECT_GT(flood, 19 * 7000) << "20x the data rate over 10 s of dual-return data";

  const auto times = sweep_times(listener);
  const auto frames = decode_capture(run / "lidar.pcap");
  std::lock_guard<std::mutex> lock(listener.mutex);
  const trajroi::status_t& last = listener.statuses.back();
  const std::int64_t kernel = counter(last, "lidar.kernel_drops");
  const std::int64_t ring = counter(last, "ring_drops.lidar");
  const std::int64_t oversize = counter(last, "lidar.oversize_datagrams");
  // Every datagram from the sensor reached the decoder or was counted where it was lost.
  EXPECT_EQ(last.lidar_packets + last.position_packets + oversize + kernel + ring, sent) << rig.logs();
  EXPECT_EQ(counter(last, "lidar.rejected_source"), foreign);
  // Malformed ones are rejected with a reason; copies are duplicates.
  const std::int64_t lost = kernel + ring;
  EXPECT_LE(last.decode_errors + oversize, malformed);
  EXPECT_GE(last.decode_errors + oversize, malformed - lost);
  EXPECT_LE(counter(last, "lidar.duplicates"), flood - malformed);
  EXPECT_GE(counter(last, "lidar.duplicates"), flood - malformed - lost);
  // A ring that dropped is named in the log with what fell behind.
  if (ring > 0) {
    EXPECT_NE(slurp(rig.daemon_log).find("dropped in the last second: lidar "), std::string::npos) << rig.logs();
  }
  std::printf(
      "flood: %lld datagrams (%lld malformed) beside %lld data packets; kernel drops %lld, ring drops %lld; "
      "RSS %ld kB before, %ld kB peak\n",
      static_cast<long long>(flood), static_cast<long long>(malformed), static_cast<long long>(data),
      static_cast<long long>(kernel), static_cast<long long>(ring), before_kb, peak_kb);
  // Resident memory: every buffer is preallocated and made resident at start (the sweeps, the
  // ring of packets decoded ahead, which a flood is the first to fill), so the flood does not
  // grow it: a few pages at most (a lazily made 1.4 MB decode-ahead ring was +1.7 MB here).
  // (ASan's allocator quarantine grows on its own: not checked there.)
  ASSERT_GT(before_kb, 0);
  if (!under_sanitizer()) {
    EXPECT_LE(peak_kb - before_kb, 256) << "kB of resident memory grown during the flood";
  }

  // Published through the flood (5 … 15 s; the scenario's own GNSS outage is 14 … 16 s),
  // and whole again after it: every sweep after the outage has every point of the capture
  // and no lost packet.
  std::size_t during = 0, published_during = 0, checked_after = 0;
  for (const auto& [idx, t] : times) {
    const bool published = listener.points.count(idx) == 1;
    if (t > 5.2 && t < 13.8) {
      ++during;
      published_during += published ? 1 : 0;
    }
    if (t > 16.6 && t < 27.0) {
      ASSERT_TRUE(published) << "sweep " << idx << " at " << t << " s";
      const trajroi::points_t& m = listener.points.at(idx);
      ASSERT_LT(static_cast<std::size_t>(idx), frames.size());
      EXPECT_EQ(m.points_in, static_cast<std::int32_t>(frames[static_cast<std::size_t>(idx)].points.size())) << idx;
      EXPECT_EQ(m.lost_packets, 0) << idx;
      ++checked_after;
    }
  }
  EXPECT_GT(during, 80U);
  // Under a sanitizer the daemon may fall behind in the flood (drops counted above); in
  // release it keeps every sweep.
  if (lost == 0) {
    EXPECT_EQ(published_during, during);
  } else {
    EXPECT_GT(published_during, during / 2);
  }
  EXPECT_GT(checked_after, 100U);
}

// The corridor fed live as its sensors would (UDP datagrams to 127.0.0.1, GNSS and IMU bytes
// through pseudo-terminals, at the recorded pace), heard over LCM by `trajroi watch --run` as
// any client hears it, and scored there against the scenario's truth (each sweep decoded again
// from the capture, its points placed with the true pose, the truth the corridor along the
// sweep's published ROI chain): every sweep published is heard, and the daemon keeps the
// corridor's points and little else. Seen on 2026-12-01: 266 of 266 sweeps heard, recall
// 0.9989, precision 1.0000 (release and ASan).
TEST(TrajroidLive, CorridorFedLiveIsScoredByTrajroiWatchAgainstTheTruth) {
  const fs::path& run = corridor_run();
  LiveRig rig(run, "WATCH", 3);
  const fs::path watch_log = rig.dir / "watch.log";
  Child watch(
      TRAJROI_CLI,
      {"watch", "--run", run.string(), "--lcm-url", kTestLcmUrl, "--channel-prefix", rig.prefix, "--seconds", "120"},
      watch_log);
  Child daemon({"--config", rig.config.string(), "--lcm-url", kTestLcmUrl}, rig.daemon_log);
  // The feed starts once the watch hears the daemon's status (each second from its start): the
  // corridor's second sweep is published 0.2 s into the data, before the watch has read the
  // run's truth (0.3 s), and a client that is not listening yet does not get it.
  ASSERT_TRUE(wait_for_text(watch_log, "status ", seconds(20))) << "the watch never heard the daemon\n" << rig.logs();
  Child feed(TRAJROI_CLI, rig.feed_args(run, {}), rig.feed_log);
  ASSERT_TRUE(stop_after_feed(rig, daemon, seconds(60)));
  // It ends at the daemon's final status.
  ASSERT_EQ(watch.wait(seconds(15)), 0) << slurp(watch_log) << rig.logs();

  // "trajroi watch: H sweeps heard of P published (W withheld …)" and "… over S sweeps:
  // precision p, recall r, accuracy a (TP …, FP …, FN …, TN …)"
  const std::string log = slurp(watch_log);
  const std::int64_t heard = count_after(log, "trajroi watch: ");
  const std::int64_t published = count_after(log, "sweeps heard of ");
  const std::int64_t scored = count_after(log, "truth over ");
  const double precision = number_after(log, "precision ");
  const double recall = number_after(log, "recall ");
  std::printf("live corridor: %lld sweeps published, %lld heard, %lld scored: precision %.5f, recall %.5f\n",
              static_cast<long long>(published), static_cast<long long>(heard), static_cast<long long>(scored),
              precision, recall);
  // 266 in an as-fast replay; live, the pose becomes valid a sweep or two later or earlier.
  EXPECT_GE(published, 255) << log << rig.logs();
  EXPECT_EQ(heard, published) << log;
  EXPECT_EQ(scored, heard) << "every sweep heard has its capture frame and ROI chain\n" << log;
  EXPECT_GE(recall, 0.995) << log;
  EXPECT_GE(precision, 0.999) << log;
}

}  // namespace
