// trajroid under control while it runs: a new trajectory over LCM (and bad ones refused with
// their reasons counted), SIGHUP re-reading the configured file, SIGTERM stopping within a
// second — all between sweeps, never inside one.
#include <cmath>
#include <limits>

#include "daemon_fixture.hpp"

namespace {

using namespace daemon_test;
using std::chrono::milliseconds;
using std::chrono::seconds;

trajroi::trajectory_t trajectory(std::int32_t id, std::vector<double> u, std::vector<double> v) {
  trajroi::trajectory_t m;
  m.id = id;
  m.coordinates = trajroi::trajectory_t::GLOBAL_XY;
  m.num_waypoints = static_cast<std::int32_t>(u.size());
  m.u = std::move(u);
  m.v = std::move(v);
  return m;
}

TEST(TrajroidControl, TrajectoryOverLcmSighupAndSigterm) {
  const std::string prefix = "TRJTEST_" + std::to_string(::getpid()) + "_CONTROL";
  const fs::path run = corridor_run();
  // The trajectory file this daemon re-reads on SIGHUP: the run's, copied.
  const fs::path trajectory_file = run / (prefix + "_trajectory.csv");
  fs::copy_file(run / "trajectory.csv", trajectory_file, fs::copy_options::overwrite_existing);
  std::string text = slurp(run / "trajroid.yaml");
  const auto at = text.find("file: trajectory.csv");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 20, "file: " + trajectory_file.filename().string());
  text += "lcm:\n  channels: {points: " + prefix + "_POINTS, pose: " + prefix + "_POSE, roi: " + prefix +
          "_ROI, status: " + prefix + "_STATUS, trajectory: " + prefix + "_TRAJECTORY}\n";
  const fs::path config = run / (prefix + ".yaml");
  std::ofstream(config) << text;

  Listener listener(prefix);
  ASSERT_TRUE(listener.good());
  // Real-time pace: the run lasts 29 s, longer than the steps below need even under TSan.
  Child child({"--config", config.string(), "--replay", run.string(), "--rate", "1", "--lcm-url", kTestLcmUrl},
              run / (prefix + ".log"));
  ASSERT_TRUE(listener.wait_for([&] { return !listener.points.empty(); }, seconds(20)))
      << slurp(run / (prefix + ".log"));

  // Refused, each for its reason; the active trajectory stays.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  listener.publish_trajectory(trajectory(0, {0, 10}, {0, 0}));
  listener.publish_trajectory(trajectory(5, {0, nan}, {0, 0}));
  listener.publish_trajectory(trajectory(6, {3, 3}, {1, 1}));
  trajroi::trajectory_t unknown = trajectory(9, {0, 10}, {0, 0});
  unknown.coordinates = 7;
  listener.publish_trajectory(unknown);
  // Accepted: a parallel line 4 m to the south.
  listener.publish_trajectory(trajectory(7, {-14, 25}, {-6, -6}));
  ASSERT_TRUE(listener.wait_for(
      [&] { return !listener.points.empty() && listener.points.rbegin()->second.trajectory_id == 7; }, seconds(10)))
      << slurp(run / (prefix + ".log"));
  std::int64_t first_new = 0;
  {
    std::lock_guard<std::mutex> lock(listener.mutex);
    for (const auto& [idx, m] : listener.points) {
      if (m.trajectory_id == 7) {
        first_new = idx;
        break;
      }
    }
    const trajroi::roi_t& roi = listener.rois.at(first_new);
    EXPECT_EQ(roi.trajectory_id, 7);
    ASSERT_EQ(roi.num_centres, 6);  // 15 m look-ahead, d = 25 % of 12 m
    for (const double cy : roi.cy)
      EXPECT_DOUBLE_EQ(cy, -6.0);
    // Before the swap, the configured trajectory; after it, only the new one.
    for (const auto& [idx, m] : listener.points)
      EXPECT_EQ(m.trajectory_id, idx < first_new ? 0 : 7) << idx;
  }

  // SIGHUP: the configured file again, from a later sweep on, under a new id (the next above 7).
  child.signal(SIGHUP);
  ASSERT_TRUE(listener.wait_for(
      [&] {
        return listener.points.rbegin()->first > first_new && listener.points.rbegin()->second.trajectory_id == 8;
      },
      seconds(10)));
  EXPECT_NE(slurp(run / (prefix + ".log")).find("SIGHUP: trajectory 8 reloaded from " + trajectory_file.string()),
            std::string::npos);

  // Malformed files on SIGHUP: each refused with its reason in the log, the active
  // trajectory (the reloaded one, id 8) stays.
  const std::string good = slurp(trajectory_file);
  std::string million;
  million.reserve(14'000'000);
  for (int i = 0; i <= 1'000'000; ++i)
    million += std::to_string(i) + ",0\n";  // one too many
  const std::vector<std::pair<std::string, std::string>> bad{
      {"0,0\n5,nan\n10,0\n", ":2: waypoint is not finite"},
      {"0,0\n", "at least two distinct waypoints, got 1"},
      {million, "1000001 waypoints, more than the limit of 1000000"},
      {"0,0\n3,4,5\n", ":2: expected 'x,y'"}};
  const fs::path log = run / (prefix + ".log");
  for (std::size_t i = 0; i < bad.size(); ++i) {
    std::ofstream(trajectory_file, std::ios::trunc) << bad[i].first;
    child.signal(SIGHUP);
    // The file is read off the publishing thread; its refusal is logged when done.
    std::string text_now;
    std::size_t refusals = 0;
    const auto until = std::chrono::steady_clock::now() + seconds(20);
    while (refusals < i + 1 && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(milliseconds(20));
      text_now = slurp(log);
      refusals = 0;
      for (auto hit = text_now.find("SIGHUP: trajectory not reloaded"); hit != std::string::npos;
           hit = text_now.find("SIGHUP: trajectory not reloaded", hit + 1)) {
        ++refusals;
      }
    }
    ASSERT_EQ(refusals, i + 1) << text_now;
    const auto refused = text_now.rfind("SIGHUP: trajectory not reloaded");
    EXPECT_NE(text_now.find(bad[i].second, refused), std::string::npos) << text_now.substr(refused);
    std::lock_guard<std::mutex> lock(listener.mutex);
    EXPECT_EQ(listener.points.rbegin()->second.trajectory_id, 8);
  }
  std::ofstream(trajectory_file, std::ios::trunc) << good;

  // SIGTERM: a clean stop within a second.
  const auto asked = std::chrono::steady_clock::now();
  child.signal(SIGTERM);
  const int code = child.wait(seconds(5));
  const double stop_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
  EXPECT_EQ(code, 0) << slurp(run / (prefix + ".log"));
  EXPECT_LT(stop_s, 1.0);
  std::this_thread::sleep_for(milliseconds(200));

  std::lock_guard<std::mutex> lock(listener.mutex);
  ASSERT_FALSE(listener.statuses.empty());
  const trajroi::status_t& last = listener.statuses.back();
  EXPECT_EQ(counter(last, "trajectory.rejected: id not positive"), 1);
  EXPECT_EQ(counter(last, "trajectory.rejected: non-finite waypoint"), 1);
  EXPECT_EQ(counter(last, "trajectory.rejected: fewer than 2 distinct waypoints"), 1);
  EXPECT_EQ(counter(last, "trajectory.rejected: unknown coordinates"), 1);
  EXPECT_EQ(counter(last, "trajectory.accepted"), 1);
  EXPECT_EQ(counter(last, "trajectory.reloads"), 1);
  EXPECT_EQ(counter(last, "trajectory.reload_errors"), 4);
  EXPECT_EQ(counter(last, "trajectory.swaps"), 2);
  EXPECT_EQ(last.ring_drops, 0);
  for (const auto& [idx, m] : listener.points) {
    ASSERT_EQ(listener.rois.count(idx), 1u);
    EXPECT_EQ(listener.rois.at(idx).trajectory_id, m.trajectory_id) << idx;
  }
}

}  // namespace
