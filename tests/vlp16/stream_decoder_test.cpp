// The stream decoder on synthetic packet streams: a simulated VLP-16 spinning at 10 Hz,
// with packets dropped, swapped, repeated, damaged or mislabelled on purpose.
#include "trajroi/vlp16/stream_decoder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "packet_builder.hpp"
#include "synthetic_sensor.hpp"

namespace trajroi::vlp16 {
namespace {

using model_test::Collector;
using stream_test::kPacketsPerTurn;
using stream_test::Outcome;
using stream_test::run;
using stream_test::Sensor;

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

}  // namespace
}  // namespace trajroi::vlp16

namespace trajroi::vlp16 {
namespace {

// A cut between two packets (at 359.95°: blocks 0.4° apart, a turn's last firing ends at
// 359.925° and the next packet's first is at 0°): the frame is delivered with the turn's last
// packet, not when the next one comes; its points are those of a frame cut there.
TEST(Vlp16Stream, AFrameWhoseCutFallsBetweenPacketsComesWithItsLastPacket) {
  StreamOptions options;
  options.cut_azimuth_deg = 359.95;
  Sensor sensor;
  StreamDecoder decoder(Calibration::vlp16_default(), options);
  Collector sink;
  std::vector<std::size_t> during;  // the packet each frame came with
  for (std::size_t i = 0; i < 3 * kPacketsPerTurn; ++i) {
    decoder.on_data_packet(sensor.next(), sensor.received(), sink);
    while (during.size() < sink.frames.size())
      during.push_back(i);
  }
  decoder.flush(sink);
  ASSERT_EQ(sink.frames.size(), 3u);  // the first (partial) and two whole; nothing left to flush
  for (std::size_t f = 0; f < 3; ++f)
    EXPECT_EQ(during[f], (f + 1) * kPacketsPerTurn - 1) << "frame " << f << ": a turn's last packet";
  EXPECT_EQ(sink.frames[1].points.size(), kPacketsPerTurn * 384);
  EXPECT_FALSE(sink.frames[1].partial);
  EXPECT_FALSE(sink.frames[2].partial);
  const auto phase = [](const Point& p) { return std::fmod(static_cast<double>(p.azimuth_deg) + 0.05, 360.0); };
  EXPECT_LT(phase(sink.frames[1].points.front()), 0.1);
  EXPECT_GT(phase(sink.frames[1].points.back()), 359.9);
}

// A motor slower than foreseen: the packet after a foreseen end still fires 0.02° before the
// cut. Those firings begin the next frame: none is lost, and no frame of a few points is cut
// off them (the wrap that follows is not taken for another end).
TEST(Vlp16Stream, FiringsBeforeTheCutAfterAForeseenEndBeginTheNextFrame) {
  StreamOptions options;
  options.cut_azimuth_deg = 359.95;
  const Outcome clean = run(Sensor{}, 3 * kPacketsPerTurn, options);
  Sensor slipped;
  StreamDecoder decoder(Calibration::vlp16_default(), options);
  Collector sink;
  for (std::size_t i = 0; i < 3 * kPacketsPerTurn; ++i) {
    if (i == kPacketsPerTurn) slipped.azimuth_cdeg = 35993;  // foreseen at 359.97°, comes at 359.93°
    decoder.on_data_packet(slipped.next(), slipped.received(), sink);
  }
  decoder.flush(sink);
  ASSERT_EQ(sink.frames.size(), clean.sink.frames.size());
  std::size_t points = 0;
  for (const Frame& f : sink.frames)
    points += f.points.size();
  EXPECT_EQ(points, 3 * kPacketsPerTurn * 384);
  EXPECT_EQ(decoder.counters().late_dropped, 0u);
  EXPECT_EQ(sink.frames[0].points.size(), clean.sink.frames[0].points.size());  // delivered at its foreseen end
  // The next frame: the firing's 3 points before the cut (lasers 0–2 at 359.93–359.947°), then a turn.
  EXPECT_FALSE(sink.frames[1].partial);
  EXPECT_EQ(sink.frames[1].points.size(), kPacketsPerTurn * 384 + 3);
}

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

}  // namespace
}  // namespace trajroi::vlp16
