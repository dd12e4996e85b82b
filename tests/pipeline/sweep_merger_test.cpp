// SweepMerger: several LiDARs' sweeps made into one per window, by input time only.
#include "trajroi/pipeline/sweep_merger.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using namespace trajroi::pipeline;

constexpr std::int64_t kMs = 1'000'000;

// What went out: each sweep's sensors, missing ones, points per sensor, first time offsets.
struct Collect final : SweepSink {
  struct Out {
    std::uint64_t index;
    std::uint32_t sensors, missing;
    std::int64_t start_ns;
    std::vector<std::uint8_t> sensor;
    std::vector<float> x;
    std::vector<std::int32_t> t;
    std::vector<std::int32_t> raw_t;
    std::vector<std::uint8_t> raw_sensor;
    bool filtered;
    std::uint32_t points_in;
    std::int64_t merge_wait_ns;
  };
  std::vector<Out> out;
  void on_sweep(Sweep& s) override {
    out.push_back({s.index,
                   s.sensors,
                   s.missing,
                   s.start_ns,
                   {s.sensor_index.begin(), s.sensor_index.end()},
                   {s.x.begin(), s.x.end()},
                   {s.time_offset_ns.begin(), s.time_offset_ns.end()},
                   {s.raw.time_offset_ns.begin(), s.raw.time_offset_ns.end()},
                   {s.raw_sensor_index.begin(), s.raw_sensor_index.end()},
                   s.filtered,
                   s.points_in,
                   s.merge_wait_ns});
  }
};

// A lane's sweep: `n` points at x = tag, times 0, 1, 2 … µs after `start_ns`; and as many raw
// points (outputs.raw_points), times 0, 2, 4 … µs.
Sweep sweep_of(std::int64_t start_ns, std::size_t n, float tag, bool filtered = true) {
  Sweep s;
  s.reserve(100, 8, 100);
  s.start_ns = start_ns;
  s.end_ns = start_ns + 100 * kMs;
  s.filtered = filtered;
  s.points_in = static_cast<std::uint32_t>(n * 2);
  for (std::size_t i = 0; i < n; ++i) {
    s.x.push_back(tag);
    s.y.push_back(0.0F);
    s.z.push_back(0.0F);
    s.intensity.push_back(1);
    s.ring.push_back(2);
    s.return_type.push_back(1);
    s.time_offset_ns.push_back(static_cast<std::int32_t>(i * 1000));
    s.raw.x.push_back(tag);
    s.raw.y.push_back(0.0F);
    s.raw.z.push_back(0.0F);
    s.raw.intensity.push_back(1);
    s.raw.ring.push_back(2);
    s.raw.return_type.push_back(1);
    s.raw.time_offset_ns.push_back(static_cast<std::int32_t>(i * 2000));
  }
  if (!filtered) s.clear_points();
  return s;
}

TEST(SweepMerger, OneSweepOfEachSensorGoesOutTogetherWithEachPointsSensor) {
  SweepMerger m(2, 100, 8, 100, MergeOptions{});
  Collect c;
  m.add(1, sweep_of(1000 * kMs + 30 * kMs, 2, 1.0F), 1100 * kMs, c);
  EXPECT_TRUE(c.out.empty());  // waits for sensor 0
  m.add(0, sweep_of(1000 * kMs, 3, 0.0F), 1105 * kMs, c);
  ASSERT_EQ(c.out.size(), 1U);
  const auto& o = c.out[0];
  EXPECT_EQ(o.sensors, 3U);
  EXPECT_EQ(o.missing, 0U);
  EXPECT_EQ(o.start_ns, 1000 * kMs);  // the earlier start
  EXPECT_EQ(o.sensor, (std::vector<std::uint8_t>{1, 1, 0, 0, 0}));
  EXPECT_EQ(o.x, (std::vector<float>{1, 1, 0, 0, 0}));
  // Times after the window's start: sensor 1's sweep began 30 ms after sensor 0's.
  EXPECT_EQ(o.t, (std::vector<std::int32_t>{30'000'000, 30'001'000, 0, 1000, 2000}));
  // The decoded points before the ROI (outputs.raw_points) count from there too, and say
  // their sensor.
  EXPECT_EQ(o.raw_t, (std::vector<std::int32_t>{30'000'000, 30'002'000, 0, 2000, 4000}));
  EXPECT_EQ(o.raw_sensor, (std::vector<std::uint8_t>{1, 1, 0, 0, 0}));
  EXPECT_EQ(o.points_in, 10U);
  EXPECT_TRUE(o.filtered);
  EXPECT_EQ(o.merge_wait_ns, 0);  // out as its last sweep joined
}

TEST(SweepMerger, ASensorLateByMoreThanTheWaitIsLeftOutAndNamedMissing) {
  MergeOptions options;
  options.max_wait_ns = 100 * kMs;
  SweepMerger m(2, 100, 8, 0, options);
  Collect c;
  m.add(0, sweep_of(0, 2, 0.0F), 1000 * kMs, c);
  m.tick(1050 * kMs, c);
  EXPECT_TRUE(c.out.empty());
  m.tick(1101 * kMs, c);  // past the wait, in input time
  ASSERT_EQ(c.out.size(), 1U);
  EXPECT_EQ(c.out[0].sensors, 1U);
  EXPECT_EQ(c.out[0].missing, 2U);
  EXPECT_EQ(m.incomplete(), 1U);
  // Its latency is the wait for sensor 1, not the processing's: the log line says so.
  EXPECT_EQ(c.out[0].merge_wait_ns, 101 * kMs);
}

TEST(SweepMerger, ASilentSensorIsNotWaitedForAndIsSaidSilent) {
  MergeOptions options;
  options.silent_ns = 500 * kMs;
  SweepMerger m(2, 100, 8, 0, options);
  Collect c;
  m.add(0, sweep_of(0, 1, 0.0F), 1000 * kMs, c);
  m.add(1, sweep_of(0, 1, 1.0F), 1010 * kMs, c);
  ASSERT_EQ(c.out.size(), 1U);
  // Sensor 1 stops; sensor 0 goes on every 100 ms.
  std::int64_t now = 1100 * kMs;
  for (int i = 0; i < 10; ++i, now += 100 * kMs) {
    m.tick(now, c);
    m.add(0, sweep_of(now, 1, 0.0F), now, c);
  }
  EXPECT_TRUE(m.silent(1, now));
  EXPECT_FALSE(m.silent(0, now));
  // Once silent (more than 0.5 s after its last sweep at 1.01 s), each of sensor 0's sweeps goes
  // out at once, without sensor 1 and without naming it missing.
  const auto& last = c.out.back();
  EXPECT_EQ(last.sensors, 1U);
  EXPECT_EQ(last.missing, 0U);
  EXPECT_EQ(c.out.size(), 11U);
  // Back: waited for again.
  m.add(1, sweep_of(now, 1, 1.0F), now + kMs, c);
  EXPECT_FALSE(m.silent(1, now + kMs));
}

TEST(SweepMerger, ASecondSweepOfOneSensorClosesTheWindow) {
  SweepMerger m(3, 100, 8, 0, MergeOptions{});
  Collect c;
  m.add(0, sweep_of(0, 1, 0.0F), 1000 * kMs, c);
  m.add(1, sweep_of(0, 1, 1.0F), 1001 * kMs, c);
  m.add(0, sweep_of(100 * kMs, 1, 0.0F), 1090 * kMs, c);
  ASSERT_EQ(c.out.size(), 1U);
  EXPECT_EQ(c.out[0].sensors, 3U);
  EXPECT_EQ(c.out[0].missing, 4U);
  EXPECT_EQ(c.out[0].merge_wait_ns, 89 * kMs);  // from sensor 1's sweep to sensor 0's next
}

TEST(SweepMerger, ASweepWithoutAValidPoseAddsNoPointsButTheOthersArePublished) {
  SweepMerger m(2, 100, 8, 0, MergeOptions{});
  Collect c;
  m.add(0, sweep_of(0, 2, 0.0F, false), 1000 * kMs, c);
  m.add(1, sweep_of(0, 3, 1.0F), 1001 * kMs, c);
  ASSERT_EQ(c.out.size(), 1U);
  EXPECT_TRUE(c.out[0].filtered);
  EXPECT_EQ(c.out[0].sensor, (std::vector<std::uint8_t>{1, 1, 1}));
}

TEST(SweepMerger, PerSensorEachSweepGoesOutAloneMarked) {
  MergeOptions options;
  options.per_sensor = true;
  SweepMerger m(2, 100, 8, 0, options);
  Collect c;
  m.add(1, sweep_of(0, 2, 1.0F), 1000 * kMs, c);
  m.add(0, sweep_of(0, 1, 0.0F), 1001 * kMs, c);
  ASSERT_EQ(c.out.size(), 2U);
  EXPECT_EQ(c.out[0].sensor, (std::vector<std::uint8_t>{1, 1}));
  EXPECT_EQ(c.out[0].sensors, 2U);
  EXPECT_EQ(c.out[1].sensor, (std::vector<std::uint8_t>{0}));
  EXPECT_EQ(c.out[1].index, 1U);
}

}  // namespace
