// SweepProcessor driven in process with the test scenario's recordings, merged by receive
// time as trajroid's replay merges them: the speed growth of the ROI, the trajectory swap at
// a sweep boundary, the pose gate without GNSS.
#include "trajroi/pipeline/sweep_processor.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "daemon_fixture.hpp"
#include "resident.hpp"
#include "trajroi/daemon/config.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/roi/trajectory.hpp"

namespace {

using namespace daemon_test;
using trajroi::daemon::DaemonConfig;
using trajroi::pipeline::ActiveTrajectory;
using trajroi::pipeline::Sweep;
using trajroi::pipeline::SweepProcessor;

struct Event {
  enum Kind { kLidar, kGnss, kImu } kind;
  trajroi::inputs::Stream stream = trajroi::inputs::Stream::kLidarData;
  std::int64_t t_ns = 0;
  std::vector<std::uint8_t> bytes;
  [[nodiscard]] trajroi::inputs::InputItem item(std::int64_t shift_ns = 0) const {
    return {stream, bytes, t_ns + shift_ns};
  }
};

// Every input of the run, in receive-time order (the daemon's own merger).
const std::vector<Event>& run_events() {
  static const std::vector<Event> events = [] {
    std::vector<Event> out;
    trajroi::inputs::RunMerger merger(corridor_run());
    trajroi::inputs::InputItem item;
    while (merger.next(item)) {
      using trajroi::inputs::Stream;
      const Event::Kind kind = item.stream == Stream::kGnss  ? Event::kGnss
                               : item.stream == Stream::kImu ? Event::kImu
                                                             : Event::kLidar;
      out.push_back(
          {kind, item.stream, item.receive_ns, std::vector<std::uint8_t>(item.bytes.begin(), item.bytes.end())});
    }
    return out;
  }();
  return events;
}

DaemonConfig run_config() {
  return trajroi::daemon::load_daemon_config(corridor_run() / "trajroid.yaml");
}

std::unique_ptr<trajroi::pipeline::ActiveTrajectory> trajectory_from(const fs::path& file, std::int32_t id) {
  return std::make_unique<trajroi::pipeline::ActiveTrajectory>(
      trajroi::pipeline::ActiveTrajectory{trajroi::roi::parse_trajectory_csv(slurp(file), file.string()), id});
}

struct Collect final : trajroi::pipeline::SweepSink {
  std::vector<trajroi::pipeline::Sweep> sweeps;
  void on_sweep(trajroi::pipeline::Sweep& s) override { sweeps.push_back(s); }
};

// Feeds the run; `before_lidar(processor, sink)` runs before each lidar datagram. `with_gnss`
// false leaves the GNSS stream out.
template <typename Hook>
Collect drive(trajroi::pipeline::SweepProcessor& processor, bool with_gnss, Hook before_lidar) {
  Collect sink;
  for (const Event& e : run_events()) {
    if (e.kind == Event::kGnss) {
      if (with_gnss) processor.process(e.item(), sink);
    } else if (e.kind == Event::kImu) {
      processor.process(e.item(), sink);
    } else {
      before_lidar(processor, sink);
      processor.process(e.item(), sink);
    }
  }
  processor.flush(sink);
  return sink;
}

Collect drive(trajroi::pipeline::SweepProcessor& processor, bool with_gnss = true) {
  return drive(processor, with_gnss, [](trajroi::pipeline::SweepProcessor&, Collect&) {});
}

// The publisher's ring takes a finished sweep's points by exchanging arrays: the header is
// copied, every array's points move, the slot's old arrays (their capacity) go back.
TEST(Sweep, TakeExchangesThePointArraysAndCopiesTheHeader) {
  trajroi::pipeline::Sweep built, slot;
  built.reserve(64, 8);
  slot.reserve(64, 8);
  built.index = 41;
  built.filtered = true;
  built.start_s_m = 12.5;
  built.centres.resize(3);
  built.x = {1.0f, 2.0f};
  built.y = {3.0f, 4.0f};
  built.z = {5.0f, 6.0f};
  built.intensity = {7, 8};
  built.ring = {9, 10};
  built.return_type = {1, 3};
  built.time_offset_ns = {11, 12};
  built.point_index = {13, 14};
  const trajroi::pipeline::Sweep expected = built;
  // Where each of the seven point arrays lives.
  const auto arrays = [](const trajroi::pipeline::Sweep& s) {
    return std::vector<const void*>{s.x.data(),
                                    s.y.data(),
                                    s.z.data(),
                                    s.intensity.data(),
                                    s.ring.data(),
                                    s.return_type.data(),
                                    s.time_offset_ns.data()};
  };
  const std::vector<const void*> built_arrays = arrays(built);
  const std::vector<const void*> slot_arrays = arrays(slot);

  slot.take(built);

  EXPECT_EQ(slot.index, 41U);
  EXPECT_TRUE(slot.filtered);
  EXPECT_EQ(slot.start_s_m, 12.5);
  EXPECT_EQ(slot.centres.size(), 3U);
  EXPECT_EQ(slot.x, expected.x);
  EXPECT_EQ(slot.y, expected.y);
  EXPECT_EQ(slot.z, expected.z);
  EXPECT_EQ(slot.intensity, expected.intensity);
  EXPECT_EQ(slot.ring, expected.ring);
  EXPECT_EQ(slot.return_type, expected.return_type);
  EXPECT_EQ(slot.time_offset_ns, expected.time_offset_ns);
  EXPECT_EQ(slot.point_index, expected.point_index);
  // Exchanged, not copied: the points live where they were built, the slot's arrays (reserved
  // alike) are the processor's for the next sweep.
  EXPECT_EQ(arrays(slot), built_arrays);
  EXPECT_EQ(arrays(built), slot_arrays);
  EXPECT_GE(built.x.capacity(), 64U);
  EXPECT_EQ(built.index, 41U);  // the processor's header is left as it was
}

// A sweep that was not made resident (an as-fast replay's) becomes so as it fills, a step of
// points at a time, and its residence goes with its arrays when the publisher's ring takes it.
TEST(Sweep, BecomesResidentAStepAtATimeAsItFillsAndTheResidenceGoesWithItsArrays) {
  using test_memory::any_resident;
  using test_memory::resident;
  constexpr std::size_t kStep = Sweep::kResidentStep;
  // 36 MB a float array: above glibc's largest mapping threshold, so its own fresh mapping.
  constexpr std::size_t kPoints = 9'000'000;
  Sweep built, slot;
  built.reserve(kPoints, 8);
  slot.reserve(kPoints, 8);
  const auto floats = [](std::size_t n) { return n * sizeof(float); };
  // Past its first 4 KB, which AddressSanitizer's malloc writes (max_malloc_fill_size).
  constexpr std::size_t kFilled = 1024;
  ASSERT_FALSE(any_resident(built.x.data() + kFilled, floats(kPoints - kFilled))) << "fresh memory expected";
  EXPECT_EQ(built.resident, 0U);

  built.make_resident_to(100);  // a whole step
  EXPECT_EQ(built.resident, kStep);
  EXPECT_TRUE(resident(built.x.data(), floats(kStep)));
  EXPECT_TRUE(resident(built.time_offset_ns.data(), kStep * sizeof(std::int32_t)));
  EXPECT_TRUE(resident(built.return_type.data(), kStep));
  EXPECT_TRUE(resident(built.sensor_index.data(), kStep));
  EXPECT_FALSE(any_resident(built.x.data() + kStep, floats(kPoints - kStep)));

  built.make_resident_to(kStep);  // already
  EXPECT_EQ(built.resident, kStep);
  built.make_resident_to(3 * kStep + 5);  // past a step: up to it
  EXPECT_EQ(built.resident, 3 * kStep + 5);
  EXPECT_TRUE(resident(built.y.data(), floats(3 * kStep)));
  EXPECT_FALSE(any_resident(built.y.data() + 3 * kStep + 1024, floats(kPoints - 3 * kStep - 1024)));

  slot.take(built);
  EXPECT_EQ(slot.resident, 3 * kStep + 5);
  EXPECT_EQ(built.resident, 0U);
  built.make_resident();
  EXPECT_EQ(built.resident, built.x.capacity());
  EXPECT_TRUE(resident(built.z.data(), floats(kPoints)));
}

TEST(SweepProcessor, TheRoiGrowsWithSpeedAndTheGrowthIsCapped) {
  DaemonConfig config = run_config();
  config.roi.look_ahead_per_mps_s = 3.0;
  config.roi.width_per_mps_s = 2.0;
  config.roi.max_speed_mps = 5.0;
  trajroi::pipeline::SweepProcessor grown(config, trajectory_from(config.trajectory_file, 0));
  const Collect free_run = drive(grown);

  DaemonConfig capped_config = config;
  capped_config.roi.max_speed_mps = 0.5;
  trajroi::pipeline::SweepProcessor capped(capped_config, trajectory_from(config.trajectory_file, 0));
  const Collect capped_run = drive(capped);
  ASSERT_EQ(free_run.sweeps.size(), capped_run.sweeps.size());

  const auto& r = config.roi;
  int cruising = 0, unknown = 0;
  for (std::size_t k = 0; k < free_run.sweeps.size(); ++k) {
    const trajroi::pipeline::Sweep& s = free_run.sweeps[k];
    if (!s.filtered) continue;
    // The formula, sweep by sweep, with the speed the sweep reports.
    const double v = s.speed_known ? std::min(s.speed_mps, r.max_speed_mps) : r.max_speed_mps;
    EXPECT_DOUBLE_EQ(s.look_ahead_m, r.look_ahead_m + 3.0 * v) << k;
    EXPECT_DOUBLE_EQ(s.radius_m, (r.circle_diameter_m + 2.0 * v) / 2.0) << k;
    const trajroi::pipeline::Sweep& c = capped_run.sweeps[k];
    ASSERT_TRUE(c.filtered);
    ASSERT_EQ(c.speed_known, s.speed_known);
    const double vc = c.speed_known ? std::min(c.speed_mps, 0.5) : 0.5;
    EXPECT_DOUBLE_EQ(c.look_ahead_m, r.look_ahead_m + 3.0 * vc) << k;
    EXPECT_LE(c.look_ahead_m, r.look_ahead_m + 1.5 + 1e-12);
    // While the robot cruises (1 m/s in the scenario from about 2 s to 28 s; sweeps are
    // 0.1 s), the estimated speed says so and the capped run is at its cap.
    if (!s.speed_known) {
      ++unknown;
      continue;
    }
    if (k >= 30 && k + 30 < free_run.sweeps.size()) {
      ++cruising;
      EXPECT_NEAR(s.speed_mps, 1.0, 0.1) << "sweep " << k;
      EXPECT_DOUBLE_EQ(c.look_ahead_m, r.look_ahead_m + 1.5) << k;
    }
  }
  EXPECT_GT(cruising, 150) << "the scenario drives 12 + 4.7 + 10 m at 1 m/s";
  EXPECT_LE(unknown, 2) << "the first sweep with a pose, and the first after the GNSS outage";
}

TEST(SweepProcessor, ATrajectoryOfferedInsideASweepTakesEffectAtTheNextOne) {
  const DaemonConfig config = run_config();
  trajroi::pipeline::SweepProcessor processor(config, trajectory_from(config.trajectory_file, 0));
  // A path 1 m beside the configured one, offered in the middle of the 60th sweep.
  const fs::path shifted = fs::temp_directory_path() / ("shifted_" + std::to_string(::getpid()) + ".csv");
  {
    const trajroi::roi::Trajectory original = trajectory_from(config.trajectory_file, 0)->trajectory;
    std::FILE* f = std::fopen(shifted.c_str(), "w");
    for (const auto& p : original.waypoints())
      std::fprintf(f, "%.17g,%.17g\n", p.x(), p.y() + 1.0);
    std::fclose(f);
  }
  std::size_t offered_during = 0;
  std::size_t datagrams_in_sweep = 0;
  std::uint64_t last_index = 0;
  bool offered = false;
  const Collect run = drive(processor, true, [&](trajroi::pipeline::SweepProcessor& p, Collect& sink) {
    if (p.current().index != last_index) {
      last_index = p.current().index;
      datagrams_in_sweep = 0;
    }
    if (!offered && sink.sweeps.size() == 60 && ++datagrams_in_sweep == 40) {
      p.offer_trajectory(trajectory_from(shifted, 9));
      offered = true;
      offered_during = sink.sweeps.size();
    }
  });
  fs::remove(shifted);
  ASSERT_TRUE(offered);
  ASSERT_GT(run.sweeps.size(), offered_during + 1);
  EXPECT_EQ(run.sweeps[offered_during].trajectory_id, 0) << "the sweep in progress keeps its trajectory";
  EXPECT_EQ(run.sweeps[offered_during + 1].trajectory_id, 9);
  EXPECT_EQ(processor.active_trajectory_id(), 9);
  EXPECT_EQ(processor.counters().trajectory_swaps, 1u);
  ASSERT_NE(processor.take_retired(), nullptr) << "the old trajectory is handed back, not freed in the loop";
  // The new chain lies on the new path: 1 m beside the old centres.
  const trajroi::pipeline::Sweep& before = run.sweeps[offered_during];
  const trajroi::pipeline::Sweep& after = run.sweeps[offered_during + 1];
  ASSERT_TRUE(before.filtered && after.filtered);
  ASSERT_FALSE(before.centres.empty());
  ASSERT_FALSE(after.centres.empty());
  EXPECT_NEAR(after.centres.front().position.y() - before.centres.front().position.y(), 1.0, 0.2);
  for (std::size_t k = offered_during + 1; k < run.sweeps.size(); ++k)
    EXPECT_EQ(run.sweeps[k].trajectory_id, 9) << k;
}

TEST(SweepProcessor, WithoutGnssNoSweepIsFilteredAndEachSaysWhy) {
  const DaemonConfig config = run_config();
  trajroi::pipeline::SweepProcessor processor(config, trajectory_from(config.trajectory_file, 0));
  const Collect run = drive(processor, false);
  ASSERT_GT(run.sweeps.size(), 200u);
  for (const trajroi::pipeline::Sweep& s : run.sweeps) {
    EXPECT_FALSE(s.filtered);
    EXPECT_EQ(s.pose_status, trajroi::pose::PoseStatus::kNoGnss);
    EXPECT_EQ(s.size(), 0u) << "no point leaves without a pose";
    EXPECT_GT(s.points_in, 0u);
  }
  EXPECT_EQ(processor.counters().sweeps_without_pose, run.sweeps.size());
  EXPECT_EQ(processor.counters().sweeps_filtered, 0u);
}

}  // namespace

namespace {

// The robot's pose jumps back to the start of the trajectory (here: the run fed twice, the
// second time shifted to follow the first, as `trajroid --replay --loop` does). Progress along
// the trajectory may not go backwards, but a robot far from where it put it is searched for
// again: the second pass places its ROI chains exactly as the first did.
TEST(SweepProcessor, APoseJumpBackAlongTheTrajectoryIsFoundAgain) {
  const auto& events = run_events();
  const std::int64_t lap_ns = events.back().t_ns - events.front().t_ns + 100'000'000;
  trajroi::pipeline::SweepProcessor processor(run_config(), trajectory_from(corridor_run() / "trajectory.csv", 0));
  Collect sink;
  for (const std::int64_t shift : {std::int64_t{0}, lap_ns}) {
    for (const Event& e : events) {
      processor.process(e.item(shift), sink);
    }
  }
  processor.flush(sink);
  EXPECT_GE(processor.counters().projection_reacquired, 1u);
  EXPECT_EQ(processor.lidar_counters().restarts, 1u);
  // Sweeps of the second pass against the first, matched by start time within the lap: the
  // same place on the trajectory (the first sweeps after the jump aside, whose speed and
  // attitude history still spans it).
  std::map<std::int64_t, const trajroi::pipeline::Sweep*> first;
  for (const trajroi::pipeline::Sweep& s : sink.sweeps) {
    if (s.filtered && s.start_ns < events.front().t_ns + lap_ns) first[s.start_ns / 10'000'000] = &s;
  }
  std::size_t compared = 0;
  for (const trajroi::pipeline::Sweep& s : sink.sweeps) {
    if (!s.filtered || s.start_ns < events.front().t_ns + lap_ns + 2'000'000'000) continue;
    const auto a = first.find((s.start_ns - lap_ns) / 10'000'000);
    if (a == first.end()) continue;
    EXPECT_NEAR(s.start_s_m, a->second->start_s_m, 0.05) << s.start_ns;
    ++compared;
  }
  EXPECT_GT(compared, 150u);
}

}  // namespace

namespace {

// outputs.raw_points: a sweep carries one in N of its decoded points (by index in the sweep),
// placed in the global frame exactly as the points the ROI was given (on_placed), whether the
// ROI kept them or not; nothing when it is off, nothing for a sweep without a pose.
struct PlacedAndSwept final : trajroi::pipeline::SweepSink {
  std::vector<trajroi::roi::PointXYZI> placed;  // the current sweep's, by index
  std::vector<std::vector<trajroi::roi::PointXYZI>> placed_by_sweep;
  std::vector<trajroi::pipeline::Sweep> sweeps;
  void on_placed(const trajroi::vlp16::Frame&, std::size_t first,
                 std::span<const trajroi::roi::PointXYZI> points) override {
    if (first == 0) placed.clear();
    placed.resize(first);
    placed.insert(placed.end(), points.begin(), points.end());
  }
  void on_sweep(trajroi::pipeline::Sweep& s) override {
    sweeps.push_back(s);
    placed_by_sweep.push_back(s.filtered ? placed : std::vector<trajroi::roi::PointXYZI>{});
    placed.clear();
  }
};

TEST(SweepProcessor, RawPointsAreOneInNOfTheDecodedPointsAsPlaced) {
  DaemonConfig config = run_config();
  config.outputs.raw_points = true;
  config.outputs.raw_points_decimation = 3;
  trajroi::pipeline::SweepProcessor processor(config, trajectory_from(config.trajectory_file, 0));
  PlacedAndSwept sink;
  for (const Event& e : run_events())
    processor.process(e.item(), sink);
  processor.flush(sink);
  std::size_t checked = 0;
  for (std::size_t k = 0; k < sink.sweeps.size(); ++k) {
    const Sweep& s = sink.sweeps[k];
    if (!s.filtered) {
      EXPECT_EQ(s.raw.size(), 0u) << "sweep " << s.index;
      continue;
    }
    const auto& placed = sink.placed_by_sweep[k];
    ASSERT_EQ(placed.size(), s.points_in) << "sweep " << s.index;
    ASSERT_EQ(s.raw.size(), (s.points_in + 2) / 3) << "sweep " << s.index;
    for (std::size_t i = 0; i < s.raw.size(); ++i) {
      ASSERT_EQ(s.raw.x[i], placed[3 * i].x) << "sweep " << s.index << " point " << 3 * i;
      ASSERT_EQ(s.raw.y[i], placed[3 * i].y);
      ASSERT_EQ(s.raw.z[i], placed[3 * i].z);
    }
    ++checked;
  }
  EXPECT_GT(checked, 200u);

  config.outputs.raw_points = false;
  trajroi::pipeline::SweepProcessor off(config, trajectory_from(config.trajectory_file, 0));
  for (const Sweep& s : drive(off).sweeps)
    ASSERT_EQ(s.raw.size(), 0u);
}

}  // namespace
