// The stream decoder on synthetic packet streams: a simulated VLP-16 spinning at 10 Hz,
// with packets dropped, swapped, repeated, damaged or mislabelled on purpose.
#include "trajroi/vlp16/stream_decoder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "model_replay.hpp"
#include "packet_builder.hpp"

namespace trajroi::vlp16 {
namespace {

// A VLP-16 at 10 Hz: 0.40° per firing, a packet every 1327.104 µs (single) or 663.552 µs
// (dual), every channel returning 2 m.
struct Sensor {
  ReturnMode mode = ReturnMode::kStrongest;
  std::uint8_t product = kProductVlp16;
  double toh_us = 1'000'000.0;
  std::uint32_t azimuth_cdeg = 0;
  std::int64_t receive_ns = 1'700'000'000'000'000'000;
  double period_us = 12 * 110.592;  // single; dual halves it
  std::uint16_t step_cdeg = 40;

  std::vector<std::uint8_t> next() {
    const bool dual = mode == ReturnMode::kDual;
    const double period = dual ? period_us / 2.0 : period_us;
    auto p = make_packet(static_cast<std::uint16_t>(azimuth_cdeg), step_cdeg, mode, product,
                         static_cast<std::uint32_t>(std::llround(toh_us)) % 3'600'000'000u);
    for (std::size_t block = 0; block < kBlocks; ++block) {
      for (std::size_t channel = 0; channel < 32; ++channel)
        set_return(p, block, channel, 1000, 10);
    }
    const std::size_t firings = dual ? kBlocks / 2 : kBlocks;
    azimuth_cdeg = (azimuth_cdeg + step_cdeg * static_cast<std::uint32_t>(firings)) % 36000;
    toh_us += period;
    receive_ns += std::llround(period * 1000.0);
    return p;
  }
  [[nodiscard]] std::int64_t received() const { return receive_ns; }
};

using model_test::Collector;

// Feeds `count` packets of `sensor`, letting `edit` drop (return false) or change each.
struct Outcome {
  Collector sink;
  StreamCounters counters;
  std::string rejection;
};
Outcome run(Sensor sensor, std::size_t count, StreamOptions options = {},
            const std::function<bool(std::size_t, std::vector<std::uint8_t>&)>& edit = {}) {
  Outcome r;
  StreamDecoder decoder(Calibration::vlp16_default(), options);
  for (std::size_t i = 0; i < count; ++i) {
    auto p = sensor.next();
    if (edit && !edit(i, p)) continue;
    decoder.on_data_packet(p, sensor.received(), r.sink);
  }
  decoder.flush(r.sink);
  r.counters = decoder.counters();
  r.rejection = decoder.model_check().reason();
  return r;
}

constexpr std::size_t kPacketsPerTurn = 75;  // 36000 / (12 × 40)

TEST(Vlp16Stream, CleanStreamGivesWholeSweepsCutAtTheConfiguredAzimuth) {
  for (const double cut_deg : {0.0, 90.0, 359.5}) {
    StreamOptions options;
    options.cut_azimuth_deg = cut_deg;
    const Outcome r = run(Sensor{}, 4 * kPacketsPerTurn + 10, options);
    EXPECT_EQ(r.counters.decoded_packets, 4 * kPacketsPerTurn + 10);
    EXPECT_EQ(r.counters.lost_packets, 0u);
    EXPECT_EQ(r.counters.clock_resets, 0u);
    ASSERT_GE(r.sink.frames.size(), 4u) << cut_deg;
    EXPECT_TRUE(r.sink.frames.front().partial);
    EXPECT_TRUE(r.sink.frames.back().partial);
    std::size_t points = 0;
    for (const Frame& f : r.sink.frames)
      points += f.points.size();
    EXPECT_EQ(points, r.counters.points);
    for (std::size_t i = 1; i + 1 < r.sink.frames.size(); ++i) {
      const Frame& f = r.sink.frames[i];
      EXPECT_FALSE(f.partial);
      EXPECT_EQ(f.points.size(), kPacketsPerTurn * 384);  // exactly one turn of firings
      // Starts at the first firing at or past the cut, ends at the last before it.
      const auto phase = [&](const Point& p) {
        return std::fmod(static_cast<double>(p.azimuth_deg) - cut_deg + 360.0, 360.0);
      };
      EXPECT_LT(phase(f.points.front()), 0.4) << cut_deg;
      EXPECT_GT(phase(f.points.back()), 359.5) << cut_deg;
      // One turn is 75 packets of 1327.104 µs; from a frame's first point to its last is that
      // less the gap between two successive points: 20.736 µs when the cut falls between
      // firings (laser 15 of sequence 2 to laser 0 of the next), 2.304 µs inside one.
      // Timestamps are whole µs.
      const auto span_ns = static_cast<double>(f.end_time_ns - f.start_time_ns);
      EXPECT_GE(span_ns, (75 * 1327.104 - 20.736) * 1e3 - 1e3) << cut_deg;
      EXPECT_LE(span_ns, (75 * 1327.104 - 2.304) * 1e3 + 1e3) << cut_deg;
      EXPECT_EQ(f.points.front().time_offset_ns, 0u);
      EXPECT_EQ(static_cast<std::int64_t>(f.points.back().time_offset_ns), f.end_time_ns - f.start_time_ns);
      EXPECT_FALSE(f.start_utc_ns.has_value());
      EXPECT_EQ(f.index, i);
    }
    EXPECT_EQ(r.counters.frames + r.counters.partial_frames, r.sink.frames.size());
  }
}

// A sensor whose head stops turning (azimuth stuck) never reaches the cut: its points are
// cut into partial frames of at most kMaxFrameDuration_ns (2 s), none lost, each point's time
// after its own frame's start.
TEST(Vlp16Stream, ASensorThatStopsTurningIsCutIntoFramesOfAtMostTwoSeconds) {
  Sensor stuck;
  stuck.step_cdeg = 0;
  constexpr std::size_t kPackets = 3768;  // 5.0 s of packets 1327.104 µs apart
  const Outcome r = run(stuck, kPackets);
  EXPECT_EQ(r.counters.decoded_packets, kPackets);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  ASSERT_EQ(r.sink.frames.size(), 3u);  // 0–2 s, 2–4 s, 4–5 s
  std::size_t points = 0;
  std::uint32_t packets = 0;
  for (std::size_t i = 0; i < r.sink.frames.size(); ++i) {
    const Frame& f = r.sink.frames[i];
    EXPECT_TRUE(f.partial) << i;
    EXPECT_EQ(f.index, i);
    points += f.points.size();
    packets += f.packets;
    EXPECT_LE(f.end_time_ns - f.start_time_ns, kMaxFrameDuration_ns) << i;
    EXPECT_EQ(f.points.front().time_offset_ns, 0u) << i;
    EXPECT_EQ(static_cast<std::int64_t>(f.points.back().time_offset_ns), f.end_time_ns - f.start_time_ns) << i;
    for (std::size_t k = 1; k < f.points.size(); ++k)
      ASSERT_GE(f.points[k].time_offset_ns, f.points[k - 1].time_offset_ns) << i << " " << k;
    if (i + 1 < r.sink.frames.size()) {
      // The next frame begins with the first point past 2 s (points are at most one block,
      // 110.592 µs, apart) and right after this one's last point.
      const Frame& next = r.sink.frames[i + 1];
      EXPECT_GT(next.start_time_ns - f.start_time_ns, kMaxFrameDuration_ns) << i;
      EXPECT_LE(next.start_time_ns - f.start_time_ns, kMaxFrameDuration_ns + 110'592) << i;
      EXPECT_GT(next.start_time_ns, f.end_time_ns) << i;
      EXPECT_LE(next.start_time_ns - f.end_time_ns, 110'592) << i;
    }
  }
  EXPECT_EQ(points, kPackets * 384);  // every channel of every packet returns
  EXPECT_EQ(packets, kPackets);       // a packet split by a cut counts in the frame of its first firing
}

TEST(Vlp16Stream, MissingPacketsAreCountedInTheirFrame) {
  const Outcome r = run(Sensor{}, 3 * kPacketsPerTurn, {}, [](std::size_t i, auto&) { return i < 100 || i > 102; });
  EXPECT_EQ(r.counters.lost_packets, 3u);
  std::uint32_t in_frames = 0;
  for (const Frame& f : r.sink.frames)
    in_frames += f.lost_packets;
  EXPECT_EQ(in_frames, 3u);
  EXPECT_EQ(r.sink.frames[1].lost_packets, 3u);  // packets 75 … 149
}

TEST(Vlp16Stream, LossAcrossTheCutStillCutsTheSweep) {
  // Packets 70 … 80 span the 0° crossing at packet 75: no point shows the wrap.
  const Outcome r = run(Sensor{}, 3 * kPacketsPerTurn, {}, [](std::size_t i, auto&) { return i < 70 || i > 80; });
  EXPECT_EQ(r.counters.lost_packets, 11u);
  ASSERT_EQ(r.sink.frames.size(), 3u);
  EXPECT_EQ(r.sink.frames[0].lost_packets, 5u);  // 70 … 74 before the cut
  EXPECT_EQ(r.sink.frames[1].lost_packets, 6u);  // 75 … 80 after it
  EXPECT_FALSE(r.sink.frames[1].partial);
  EXPECT_EQ(r.sink.frames[1].points.size(), (kPacketsPerTurn - 6) * 384);
  EXPECT_EQ(r.sink.frames[1].packets, kPacketsPerTurn - 6);
}

TEST(Vlp16Stream, AzimuthJumpWithoutATimestampGapCountsLoss) {
  // A sensor whose clock stands still between packets 40 and 41 (timestamps repeat their
  // spacing) but whose rotation skipped two packets' worth of azimuth.
  Sensor sensor;
  StreamDecoder decoder(Calibration::vlp16_default(), {});
  Collector sink;
  for (std::size_t i = 0; i < 60; ++i) {
    auto p = sensor.next();
    if (i == 40) sensor.azimuth_cdeg = (sensor.azimuth_cdeg + 2 * 480) % 36000;
    decoder.on_data_packet(p, sensor.received(), sink);
  }
  EXPECT_EQ(decoder.counters().lost_packets, 2u);
}

TEST(Vlp16Stream, SwappedPacketsAreOutOfOrderNotLost) {
  std::vector<std::uint8_t> held;
  Sensor sensor;
  StreamDecoder decoder(Calibration::vlp16_default(), {});
  Collector sink;
  for (std::size_t i = 0; i < 2 * kPacketsPerTurn; ++i) {
    auto p = sensor.next();
    if (i == 90) {
      held = p;  // delivered after packet 91
      continue;
    }
    decoder.on_data_packet(p, sensor.received(), sink);
    if (i == 91) decoder.on_data_packet(held, sensor.received(), sink);
  }
  decoder.flush(sink);
  EXPECT_EQ(decoder.counters().out_of_order, 1u);
  EXPECT_EQ(decoder.counters().lost_packets, 0u);
  EXPECT_EQ(decoder.counters().late_dropped, 0u);
  EXPECT_EQ(decoder.counters().points, 2 * kPacketsPerTurn * 384);
  EXPECT_EQ(sink.frames[1].points.size(), kPacketsPerTurn * 384);  // nothing lost from the sweep
  EXPECT_EQ(sink.frames[1].lost_packets, 0u);
}

TEST(Vlp16Stream, RepeatedPacketIsADuplicate) {
  Sensor sensor;
  StreamDecoder decoder(Calibration::vlp16_default(), {});
  Collector sink;
  for (std::size_t i = 0; i < 20; ++i) {
    auto p = sensor.next();
    decoder.on_data_packet(p, sensor.received(), sink);
    if (i == 5) decoder.on_data_packet(p, sensor.received(), sink);
  }
  EXPECT_EQ(decoder.counters().duplicates, 1u);
  EXPECT_EQ(decoder.counters().decoded_packets, 20u);
}

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

TEST(Vlp16Stream, DualReturnStreamHasHalfThePeriod) {
  Sensor sensor;
  sensor.mode = ReturnMode::kDual;
  const Outcome r = run(sensor, 4 * kPacketsPerTurn);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  for (std::size_t i = 1; i + 1 < r.sink.frames.size(); ++i) {
    EXPECT_EQ(r.sink.frames[i].return_mode, ReturnMode::kDual);
    EXPECT_EQ(r.sink.frames[i].packets, 2 * kPacketsPerTurn);
    // Both returns 2 m: one kBoth point per firing channel.
    EXPECT_EQ(r.sink.frames[i].points.size(), kPacketsPerTurn * 384);
  }
}

TEST(Vlp16Stream, ProductId0x21WithVlp16TimingIsAcceptedAndItsFirstPacketKept) {
  Sensor sensor;
  sensor.product = kProductHdl32e;
  const Outcome r = run(sensor, 10);
  EXPECT_EQ(r.counters.rejected_total(), 0u) << r.rejection;
  EXPECT_EQ(r.counters.decoded_packets, 10u);
  EXPECT_EQ(r.counters.points, 10u * 384u);
}

TEST(Vlp16Stream, ProductId0x21WithHdl32eTimingIsRejectedWithTheReason) {
  Sensor sensor;
  sensor.product = kProductHdl32e;
  sensor.period_us = 12 * 46.08;  // 552.96 µs
  sensor.step_cdeg = 17;          // 0.17° per firing at 10 Hz
  const Outcome r = run(sensor, 10);
  EXPECT_EQ(r.counters.rejected[static_cast<std::size_t>(PacketError::kUnsupportedProduct)], 10u);
  EXPECT_EQ(r.counters.decoded_packets, 0u);
  EXPECT_NE(r.rejection.find("HDL-32E"), std::string::npos);
  EXPECT_NE(r.rejection.find("553 µs"), std::string::npos) << r.rejection;
}

TEST(Vlp16Stream, ProductId0x21RightPeriodWrongRotationIsRejected) {
  Sensor sensor;
  sensor.product = kProductHdl32e;
  sensor.step_cdeg = 5;  // 0.05° per firing: 1.25 Hz, no VLP-16 spins that slowly
  const Outcome r = run(sensor, 5);
  EXPECT_EQ(r.counters.decoded_packets, 0u);
  EXPECT_EQ(r.counters.rejected_total(), 5u);
}

TEST(Vlp16Stream, DamagedPacketsAreCountedByReasonAndTheRestDecoded) {
  const Outcome r = run(Sensor{}, 40, {}, [](std::size_t i, std::vector<std::uint8_t>& p) {
    if (i == 3) p.resize(1000);
    if (i == 4) p[500] = 0x00;  // block 5 flag
    if (i == 5) p[1204] = 0x3A;
    if (i == 6) p[1205] = 0x28;
    if (i == 7) {
      p[202] = 0xFF;  // block 2 azimuth 0xFFFF
      p[203] = 0xFF;
    }
    return true;
  });
  using E = PacketError;
  for (const E e :
       {E::kWrongSize, E::kBadBlockFlag, E::kUnknownReturnMode, E::kUnsupportedProduct, E::kAzimuthOutOfRange}) {
    EXPECT_EQ(r.counters.rejected[static_cast<std::size_t>(e)], 1u) << to_string(e);
  }
  EXPECT_EQ(r.counters.decoded_packets, 35u);
  EXPECT_EQ(r.counters.lost_packets, 5u);  // the stream has a 5-packet hole
  EXPECT_NE(r.rejection.find("0x28 (VLP-32C)"), std::string::npos);
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

}  // namespace
}  // namespace trajroi::vlp16

namespace trajroi::vlp16 {
namespace {

// The firmware writes 36000 for a block fired exactly at the wrap (before writing 0): that is
// 0°, the packet is kept whole and nothing is lost (ros-drivers/velodyne, VeloView: modulo).
TEST(Vlp16Stream, ABlockAzimuthOf36000IsZeroNotALostPacket) {
  const Outcome clean = run(Sensor{}, 3 * kPacketsPerTurn);
  const Outcome r = run(Sensor{}, 3 * kPacketsPerTurn, {}, [](std::size_t i, std::vector<std::uint8_t>& p) {
    if (i == kPacketsPerTurn) {  // block 0 of this packet fires at 0°
      EXPECT_EQ(p[2] | (p[3] << 8), 0);
      p[2] = 0xA0;  // 36000 = 0x8CA0
      p[3] = 0x8C;
    }
    return true;
  });
  EXPECT_EQ(r.counters.rejected[static_cast<std::size_t>(PacketError::kAzimuthOutOfRange)], 0u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  EXPECT_EQ(r.counters.decoded_packets, clean.counters.decoded_packets);
  ASSERT_EQ(r.sink.frames.size(), clean.sink.frames.size());
  for (std::size_t f = 0; f < r.sink.frames.size(); ++f)
    EXPECT_EQ(r.sink.frames[f].points.size(), clean.sink.frames[f].points.size()) << f;
  // Above 36000 stays out of range.
  auto p = make_packet(0, 40, ReturnMode::kStrongest);
  p[2] = 0xA1;
  p[3] = 0x8C;
  EXPECT_EQ(validate_data_packet(p), PacketError::kAzimuthOutOfRange);
  p[2] = 0xA0;
  EXPECT_EQ(validate_data_packet(p), PacketError::kNone);
  EXPECT_EQ(block_azimuth(p, 0), 0);
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
  const auto frames = received_late(kPackets, [](std::size_t i) { return static_cast<std::int64_t>(i % 5) * 100'000; },
                                    100.0);
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
