// The stream decoder's clock on synthetic packet streams: the sensor's top-of-hour time tied
// to the receive clock (its wrap, restarts, jumps, late packets and drift) and to UTC by the
// position packets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "packet_builder.hpp"
#include "synthetic_sensor.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16 {
namespace {

using model_test::Collector;
using stream_test::kPacketsPerTurn;
using stream_test::Outcome;
using stream_test::run;
using stream_test::Sensor;

TEST(Vlp16Stream, TopOfHourWrapIsNotALossNorAClockReset) {
  Sensor sensor;
  sensor.toh_us = 3'600'000'000.0 - 30 * 1327.104;  // wraps after 30 packets
  const Outcome r = run(sensor, 2 * kPacketsPerTurn);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  EXPECT_EQ(r.counters.out_of_order, 0u);
  EXPECT_EQ(r.counters.clock_resets, 0u);
  EXPECT_EQ(r.counters.decoded_packets, 2 * kPacketsPerTurn);
}

// The sensor's clock starts again (a power cycle, or a replay looping) while the receive
// clock goes on: a restart, not 30 s of out-of-order packets; the new stream decodes whole.
TEST(Vlp16Stream, SensorTimeJumpingBackIsARestartNotReordering) {
  Sensor sensor;
  sensor.toh_us = 31'000'000.0;
  StreamDecoder decoder(Calibration::vlp16_default(), {});
  Collector sink;
  for (std::size_t i = 0; i < 3 * kPacketsPerTurn; ++i) {
    if (i == 2 * kPacketsPerTurn + 20) sensor.toh_us -= 30'000'000.0;  // back 30 s, mid-sweep
    auto p = sensor.next();
    decoder.on_data_packet(p, sensor.received(), sink);
  }
  for (std::size_t i = 0; i < 3 * kPacketsPerTurn; ++i) {
    auto p = sensor.next();
    decoder.on_data_packet(p, sensor.received(), sink);
  }
  decoder.flush(sink);
  const StreamCounters& c = decoder.counters();
  EXPECT_EQ(c.restarts, 1u);
  EXPECT_EQ(c.out_of_order, 0u);
  EXPECT_EQ(c.late_dropped, 0u);
  EXPECT_EQ(c.lost_packets, 0u);
  EXPECT_EQ(c.decoded_packets, 6 * kPacketsPerTurn);
  // Frames: 0 partial, 1 whole, 2 cut by the restart (partial), then the new stream: its first
  // partial, whole turns, the last partial. Points go on in the receive clock.
  ASSERT_GE(sink.frames.size(), 6u);
  EXPECT_TRUE(sink.frames[2].partial);
  EXPECT_EQ(sink.frames[2].points.size(), 20u * 384);
  EXPECT_TRUE(sink.frames[3].partial);
  for (std::size_t i = 4; i + 1 < sink.frames.size(); ++i) {
    EXPECT_FALSE(sink.frames[i].partial) << i;
    EXPECT_EQ(sink.frames[i].points.size(), kPacketsPerTurn * 384) << i;
    EXPECT_GT(sink.frames[i].start_time_ns, sink.frames[i - 1].end_time_ns) << i;
  }
}

TEST(Vlp16Stream, LockedPositionPacketsGiveFramesTheirUtcStart) {
  Sensor sensor;
  sensor.toh_us = 1'082'000'000.0;  // 08:18:02.000 on the sensor's hour clock
  StreamDecoder decoder(Calibration::vlp16_default(), {});
  const auto position = make_position_packet(
      1'082'000'500, 2, "$GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.034,212.5,210116,0.0,E,A*2E\r\n");
  decoder.on_position_packet(position);
  ASSERT_TRUE(decoder.utc_clock().locked());
  Collector sink;
  for (std::size_t i = 0; i <= 2 * kPacketsPerTurn; ++i) {
    const auto p = sensor.next();
    decoder.on_data_packet(p, sensor.received(), sink);
  }
  ASSERT_GE(sink.frames.size(), 2u);
  const Frame& f = sink.frames[1];
  ASSERT_TRUE(f.start_utc_ns.has_value());
  // 2016-01-21 08:00:00 UTC = 1453363200 s; the sweep starts at packet 75, 0.0995 s in.
  const double expected_s = 1453363200.0 + 1082.0 + 75 * 1327.104e-6;
  EXPECT_NEAR(static_cast<double>(*f.start_utc_ns) * 1e-9, expected_s, 2e-6);
}

// The sensor's clock jumping forward 10 s between two packets 1.3 ms apart on the host is no
// loss of 7 500 packets: it is counted as a clock jump, and nothing as lost.
TEST(Vlp16Stream, ASensorClockJumpIsCountedAsSuchNotAsLostPackets) {
  const Outcome r = run(Sensor{}, 3 * kPacketsPerTurn, {}, [](std::size_t i, std::vector<std::uint8_t>& p) {
    if (i >= 100) {
      std::uint32_t toh = static_cast<std::uint32_t>(p[1200]) | (static_cast<std::uint32_t>(p[1201]) << 8) |
                          (static_cast<std::uint32_t>(p[1202]) << 16) | (static_cast<std::uint32_t>(p[1203]) << 24);
      toh += 10'000'000;
      for (std::size_t k = 0; k < 4; ++k)
        p[1200 + k] = static_cast<std::uint8_t>(toh >> (8 * k));
    }
    return true;
  });
  EXPECT_EQ(r.counters.clock_jumps, 1u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  // A real gap (packets missing, the host's time passing with them) is still loss.
  const Outcome lost = run(Sensor{}, 3 * kPacketsPerTurn, {}, [](std::size_t i, auto&) { return i < 100 || i > 102; });
  EXPECT_EQ(lost.counters.clock_jumps, 0u);
  EXPECT_EQ(lost.counters.lost_packets, 3u);
}

// Feeds `count` packets of `sensor`, each received `delay_ns(i)` after it was sent (the
// sensor's own clock running `ppm` slow against the host's), and answers the frames.
std::vector<Frame> received_late(std::size_t count, const std::function<std::int64_t(std::size_t)>& delay_ns,
                                 double ppm = 0.0) {
  Sensor sensor;
  Collector sink;
  StreamDecoder decoder(Calibration::vlp16_default(), {});
  const std::int64_t t0 = sensor.received();
  for (std::size_t i = 0; i < count; ++i) {
    auto p = sensor.next();
    const auto sent = static_cast<double>(sensor.received() - t0) * (1.0 + ppm * 1e-6);
    decoder.on_data_packet(p, t0 + std::llround(sent) + delay_ns(i), sink);
  }
  decoder.flush(sink);
  EXPECT_EQ(decoder.counters().clock_resets, 0u);
  return sink.frames;
}

// Receive delays only ever add latency, so the sweeps are timed by the least of them: a first
// packet that waited 30 ms in a busy host's socket (and jitter of up to 2 ms on the others)
// costs the first sweep its time, not every sweep after it (each was 30 ms late before).
TEST(Vlp16Stream, ALateFirstPacketDoesNotMakeEverySweepLate) {
  const auto on_time = received_late(6 * kPacketsPerTurn, [](std::size_t) { return 0; });
  const auto late = received_late(6 * kPacketsPerTurn, [](std::size_t i) -> std::int64_t {
    if (i == 0) return 30'000'000;
    return i % 7 == 0 ? 0 : static_cast<std::int64_t>((i * 7919) % 2'000'000);
  });
  ASSERT_EQ(late.size(), on_time.size());
  ASSERT_GE(on_time.size(), 6u);
  EXPECT_NEAR(static_cast<double>(late[0].start_time_ns - on_time[0].start_time_ns), 30e6, 1e3);
  for (std::size_t k = 1; k < late.size(); ++k) {
    EXPECT_NEAR(static_cast<double>(late[k].start_time_ns - on_time[k].start_time_ns), 0.0, 1e3) << "sweep " << k;
    EXPECT_EQ(late[k].points.size(), on_time[k].points.size());
    EXPECT_EQ(late[k].end_time_ns - late[k].start_time_ns, on_time[k].end_time_ns - on_time[k].start_time_ns);
  }
}

// A sensor clock running 100 ppm slow drifts 2.5 ms from the host's in 25 s: the anchor
// follows it a window or two behind (5 s, 0.5 ms of drift each) instead of holding the first
// packet's offset (2.5 ms off at the end).
TEST(Vlp16Stream, TheAnchorFollowsASlowSensorClock) {
  constexpr std::size_t kPackets = 25 * 10 * kPacketsPerTurn;  // 25 s at 10 Hz
  const auto frames = received_late(
      kPackets, [](std::size_t i) { return static_cast<std::int64_t>(i % 5) * 100'000; }, 100.0);
  const auto on_time = received_late(kPackets, [](std::size_t) { return 0; });
  ASSERT_EQ(frames.size(), on_time.size());
  double worst_ms = 0.0;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    // Where the host's clock has the sweep's first firing: 100 ppm later than the sensor says.
    const auto since = static_cast<double>(on_time[k].start_time_ns - on_time[0].start_time_ns);
    const double truth = static_cast<double>(on_time[0].start_time_ns) + since * (1.0 + 100e-6);
    worst_ms = std::max(worst_ms, std::abs(static_cast<double>(frames[k].start_time_ns) - truth) / 1e6);
  }
  EXPECT_LT(worst_ms, 1.1);
  EXPECT_GT(worst_ms, 0.4);  // the drift is real: the anchor moves in steps
}

}  // namespace
}  // namespace trajroi::vlp16
