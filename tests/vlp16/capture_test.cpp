// Real third-party captures (../shared/data/velodyne, see its README), replayed through the
// pcap source and the stream decoder; content checked against independent references: the
// data README's counts (made with a separate walker), MRPT's unit test, the GPRMC sentence,
// and nebula's reference cloud.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <thread>
#include <tuple>

#include "pcd_reader.hpp"
#include "test_data.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16 {
namespace {

struct Collector final : FrameSink {
  std::vector<Frame> frames;
  void on_frame(const Frame& frame) override { frames.push_back(frame); }
};

struct Replay {
  std::size_t data_datagrams = 0;
  std::size_t position_datagrams = 0;
  std::size_t wraps = 0;  // block azimuth decreasing from one block to the next
  std::map<std::uint8_t, std::size_t> modes;
  Collector frames;
  StreamCounters counters;
  std::string model_rejection;
  std::uint32_t model_period_us = 0;  // that decided a 0x21 stream
  std::optional<PositionPacket> first_rmc, last_rmc;
};

// `ahead`: every data packet that validates is also decoded by it first and handed over with
// its points (as trajroid's input threads decode ahead of the stream).
Replay replay(const std::filesystem::path& path, const Calibration& calibration = Calibration::vlp16_default(),
              StreamOptions options = {}, const PacketDecoder* ahead = nullptr) {
  Replay r;
  DecodedPacket decoded;
  PcapSource source(path);
  StreamDecoder decoder(calibration, options);
  Datagram datagram;
  PacketSource::Next next;
  std::optional<std::uint16_t> last_azimuth;
  while ((next = source.next(datagram)) == PacketSource::Next::kDatagram) {
    if (datagram.destination_port == kPositionPort) {
      ++r.position_datagrams;
      decoder.on_position_packet(datagram.payload);
      continue;
    }
    ++r.data_datagrams;
    if (validate_data_packet(datagram.payload) == PacketError::kNone) {
      ++r.modes[return_mode_byte(datagram.payload)];
      for (std::size_t block = 0; block < kBlocks; ++block) {
        const std::uint16_t azimuth = block_azimuth(datagram.payload, block);
        if (last_azimuth && azimuth < *last_azimuth) ++r.wraps;
        last_azimuth = azimuth;
      }
    }
    const bool decode_ahead = ahead != nullptr && validate_data_packet(datagram.payload) == PacketError::kNone;
    if (decode_ahead) {
      decoded.points.clear();
      decoded.result = ahead->decode(datagram.payload, decoded.points);
    }
    decoder.on_data_packet(datagram.payload, datagram.receive_time_ns, r.frames, decode_ahead ? &decoded : nullptr);
  }
  EXPECT_EQ(next, PacketSource::Next::kEnd) << source.error();
  decoder.flush(r.frames);
  r.counters = decoder.counters();
  r.model_rejection = decoder.model_check().reason();
  r.model_period_us = decoder.model_check().measured_period_us();
  r.first_rmc = decoder.first_rmc();
  r.last_rmc = decoder.last_rmc();
  return r;
}

std::int64_t utc_ns(int y, unsigned mo, unsigned d, int h, int mi, int s) {
  namespace c = std::chrono;
  const c::sys_days date{c::year{y} / c::month{mo} / c::day{d}};
  return (c::duration_cast<c::nanoseconds>(date.time_since_epoch()) + c::hours{h} + c::minutes{mi} + c::seconds{s})
      .count();
}

TEST(Vlp16Capture, MrptStrongestCaptureMatchesTheReadmeAndMrptsScanCount) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, 293u);
  EXPECT_EQ(r.position_datagrams, 57u);
  EXPECT_EQ(r.counters.decoded_packets, 293u);
  EXPECT_EQ(r.counters.rejected_total(), 0u);
  EXPECT_EQ(r.modes.at(0x37), 293u);
  // README: 73,486 of the 112,512 channel returns are non-zero; range limits are off.
  EXPECT_EQ(r.counters.points, 73'486u);
  EXPECT_EQ(r.counters.points + r.counters.no_return, 293u * 384u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  EXPECT_EQ(r.counters.out_of_order, 0u);

  // MRPT's unit test counts 4 scans (azimuth wraps): between the first and the last partial
  // sweeps lie wraps − 1 whole ones.
  EXPECT_EQ(r.wraps, 4u);
  EXPECT_EQ(r.counters.frames, r.wraps - 1);
  EXPECT_EQ(r.counters.partial_frames, 2u);
  ASSERT_EQ(r.frames.frames.size(), r.wraps + 1);
  std::size_t points_in_frames = 0;
  for (const Frame& f : r.frames.frames) {
    points_in_frames += f.points.size();
    EXPECT_EQ(f.return_mode, ReturnMode::kStrongest);
    EXPECT_EQ(f.lost_packets, 0u);
  }
  EXPECT_EQ(points_in_frames, r.counters.points);
  for (std::size_t i = 1; i + 1 < r.frames.frames.size(); ++i) {
    const Frame& f = r.frames.frames[i];
    EXPECT_FALSE(f.partial);
    // A whole sweep at ~10 Hz: ~75 packets, ~0.1 s, azimuths from the cut (0°) round to it.
    EXPECT_NEAR(static_cast<double>(f.packets), 75.0, 3.0);
    EXPECT_NEAR(static_cast<double>(f.end_time_ns - f.start_time_ns) * 1e-9, 0.1, 0.005);
    EXPECT_LT(f.points.front().azimuth_deg, 1.0f);
    EXPECT_GT(f.points.back().azimuth_deg, 359.0f);
    EXPECT_EQ(f.points.front().time_offset_ns, 0u);
    ASSERT_TRUE(f.start_utc_ns.has_value());
    // The sweeps lie in 2016-01-21 08:18:02–04 UTC, the GPRMC's second and after.
    EXPECT_GE(*f.start_utc_ns, utc_ns(2016, 1, 21, 8, 18, 2));
    EXPECT_LT(*f.start_utc_ns, utc_ns(2016, 1, 21, 8, 18, 5));
  }
  EXPECT_TRUE(r.frames.frames.front().partial);
  EXPECT_TRUE(r.frames.frames.back().partial);

  // $GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.034,212.5,210116,0.0,E,A*2E
  EXPECT_EQ(r.counters.nmea[static_cast<std::size_t>(NmeaError::kNone)], 57u);
  ASSERT_TRUE(r.first_rmc.has_value());
  EXPECT_EQ(r.first_rmc->pps, PpsStatus::kLocked);
  EXPECT_TRUE(r.first_rmc->rmc.valid);
  EXPECT_EQ(r.first_rmc->rmc.utc_ns, utc_ns(2016, 1, 21, 8, 18, 2));
  EXPECT_DOUBLE_EQ(r.first_rmc->rmc.latitude_deg, 36.0 + 49.7478558 / 60.0);
  EXPECT_DOUBLE_EQ(r.first_rmc->rmc.longitude_deg, -(2.0 + 24.4542928 / 60.0));
  ASSERT_TRUE(r.last_rmc.has_value());
  EXPECT_GE(r.last_rmc->rmc.utc_ns, r.first_rmc->rmc.utc_ns);
}

TEST(Vlp16Capture, EarlyFirmwareProductId0x21WithVlp16TimingDecodesAsVlp16) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/rust-lidar-utils_velodyne_vlp16_2014_productid0x21.pcap");
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, 84u);
  EXPECT_EQ(r.position_datagrams, 16u);
  EXPECT_EQ(r.counters.rejected_total(), 0u) << r.model_rejection;
  EXPECT_EQ(r.counters.decoded_packets, 84u);  // the held first packet included
  // Decided on a VLP-16 single-return period (README: TOH step 1327/1328 µs).
  EXPECT_GE(r.model_period_us, 1327u);
  EXPECT_LE(r.model_period_us, 1328u);
  EXPECT_GT(r.counters.points, 0u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  EXPECT_EQ(r.wraps, 1u);
  EXPECT_EQ(r.counters.frames, 0u);  // 1 wrap: two partial sweeps
  EXPECT_EQ(r.counters.partial_frames, 2u);
  // Position packets with PPS 0 and no NMEA: no RMC, no UTC.
  EXPECT_EQ(r.counters.nmea[static_cast<std::size_t>(NmeaError::kEmpty)], 16u);
  EXPECT_FALSE(r.first_rmc.has_value());
  EXPECT_FALSE(r.frames.frames.front().start_utc_ns.has_value());
}

TEST(Vlp16Capture, Vlp16Example2018Decodes) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/rust-lidar-utils_velodyne_example_2018.pcap");
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, 84u);
  EXPECT_EQ(r.counters.decoded_packets, 84u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
}

struct RejectedCapture {
  const char* file;
  std::size_t data_packets;
  const char* reason;
};

class Vlp16RejectsOtherModels : public testing::TestWithParam<RejectedCapture> {};

TEST_P(Vlp16RejectsOtherModels, EveryPacketRejectedWithTheReason) {
  TRAJROI_REQUIRE_DATA(path, GetParam().file);
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, GetParam().data_packets);
  EXPECT_EQ(r.counters.rejected[static_cast<std::size_t>(PacketError::kUnsupportedProduct)], GetParam().data_packets);
  EXPECT_EQ(r.counters.decoded_packets, 0u);
  EXPECT_EQ(r.counters.points, 0u);
  EXPECT_TRUE(r.frames.frames.empty());
  EXPECT_NE(r.model_rejection.find(GetParam().reason), std::string::npos) << r.model_rejection;
}

INSTANTIATE_TEST_SUITE_P(
    Captures, Vlp16RejectsOtherModels,
    testing::Values(RejectedCapture{"velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap", 500,
                                    "product id 0x21 (HDL-32E) sends HDL-32E packets (told by its timing: 553 µs "
                                    "between packets), but lidar.model is vlp16: dropped (set lidar.model: hdl32e, "
                                    "or auto)"},
                    RejectedCapture{"velodyne/other_models/rust-lidar-utils_velodyne_vlp32_ACTUALLY_HDL-32E.pcap", 91,
                                    "product id 0x21 (HDL-32E) sends HDL-32E packets"},
                    RejectedCapture{"velodyne/other_models/nebula_vlp32c_strongest_1713492677.DERIVED.pcap", 379,
                                    "product id 0x28 (VLP-32C) sends VLP-32C packets, but lidar.model is vlp16"}));

// The reader thread's early wake-up: every whole frame the decoder completes on a real capture
// is completed by a packet may_complete_frame foresaw, at cuts all round; and it foresees few
// (a packet or two per sweep; a wake-up per packet is what it saves). The strongest-return and
// the dual-return capture (the 2018 example holds less than a sweep).
class Vlp16ForeseesFrameEnds : public testing::TestWithParam<const char*> {};

TEST_P(Vlp16ForeseesFrameEnds, EveryWholeFrameEndsOnAForeseenPacket) {
  TRAJROI_REQUIRE_DATA(path, GetParam());
  struct Ends final : FrameSink {
    std::size_t whole = 0;
    void on_frame(const Frame& frame) override { whole += frame.partial ? 0 : 1; }
  };
  for (const double cut : {0.0, 90.0, 180.5, 271.37, 359.99, -45.0}) {
    PcapSource source(path);
    StreamOptions options;
    options.cut_azimuth_deg = cut;
    StreamDecoder decoder(Calibration::vlp16_default(), options);
    const std::uint16_t cut_cdeg = cut_centidegrees(cut);
    Ends ends;
    std::size_t packets = 0, foreseen = 0;
    Datagram datagram;
    while (source.next(datagram) == PacketSource::Next::kDatagram) {
      if (datagram.destination_port == kPositionPort) continue;
      ++packets;
      const bool may_end = may_complete_frame(datagram.payload, cut_cdeg);
      foreseen += may_end ? 1 : 0;
      const std::size_t before = ends.whole;
      decoder.on_data_packet(datagram.payload, datagram.receive_time_ns, ends);
      if (ends.whole != before) {
        EXPECT_TRUE(may_end) << "cut " << cut << "°, data packet " << packets;
      }
    }
    EXPECT_GE(ends.whole, 2u) << "cut " << cut << "°";
    EXPECT_LE(foreseen, 3 * (ends.whole + 1)) << "cut " << cut << "°, " << packets << " packets";
  }
}

INSTANTIATE_TEST_SUITE_P(Captures, Vlp16ForeseesFrameEnds,
                         testing::Values("velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap",
                                         "velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap"));

TEST(Vlp16Stream, CutCentidegreesWrapsAndRounds) {
  EXPECT_EQ(cut_centidegrees(0.0), 0);
  EXPECT_EQ(cut_centidegrees(359.996), 0);
  EXPECT_EQ(cut_centidegrees(-45.0), 31500);
  EXPECT_EQ(cut_centidegrees(720.25), 25);
  EXPECT_EQ(cut_centidegrees(std::numeric_limits<double>::quiet_NaN()), 0);
}

// nebula's return types (nebula_common.hpp): IDENTICAL 6 when the pair's returns are equal
// or the other one is empty; otherwise FIRST_* (4, 9) for the farther return, which is the
// last one, and LAST_* (5, 10) for the nearer, the strongest that is not the last.
bool same_return(std::uint32_t nebula, ReturnType ours) {
  switch (nebula) {
    case 6:
      return true;  // kBoth, or a kLast / kStrongest whose partner was empty
    case 4:
    case 9:
      return ours == ReturnType::kLast;
    case 5:
    case 10:
      return ours == ReturnType::kStrongest;
    default:
      return false;
  }
}

// nebula's reference cloud of one dual-return sweep (14,831 points), made by its VLP-16
// decoder with the calibration YAML, min range 0.3 m. Every reference point must be one of
// ours: same ring ("channel"), same raw distance, intensity and return, a time consistent
// with nebula's time_stamp (ns since its scan start), and the same position within 1 mm.
//
// Azimuth: nebula rounds the interpolated azimuth to 0.01°, and for some firings it does
// not interpolate (its azimuth step is 0 for the last block pair of a dual packet, and its
// odd blocks take the next pair's azimuth). Its `azimuth` field says which azimuth it used.
// Where that equals ours (to its 0.01° rounding), our x/y/z are compared directly; where it
// does not, our point is first turned about z by the azimuth difference, which compares
// range, elevation and calibration with nebula's and leaves out only its interpolation.
TEST(Vlp16Capture, NebulaDualReturnReferenceCloudIsReproducedPointForPoint) {
  TRAJROI_REQUIRE_DATA(capture, "velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap");
  TRAJROI_REQUIRE_DATA(yaml, "velodyne/vlp16/nebula_VLP16_calibration.yaml");
  TRAJROI_REQUIRE_DATA(pcd, "velodyne/vlp16/nebula_vlp16_dual_reference_1673400472138016708.pcd");
  const Calibration calibration = parse_calibration_yaml(test::read_file(yaml), yaml.string());
  StreamOptions options;
  options.decode.min_range_m = 0.3;  // nebula's test parameters
  options.decode.max_range_m = 300.0;
  const Replay r = replay(capture, calibration, options);
  EXPECT_EQ(r.data_datagrams, 603u);
  EXPECT_EQ(r.modes.at(0x39), 603u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  EXPECT_EQ(r.wraps, 4u);
  EXPECT_EQ(r.counters.frames + r.counters.partial_frames, r.wraps + 1);

  const test::PcdCloud reference = test::read_pcd(pcd);
  ASSERT_EQ(reference.points(), 14'831u);
  const auto x = reference.floats("x"), y = reference.floats("y"), z = reference.floats("z");
  const auto azimuth_rad = reference.floats("azimuth");
  const auto distance = reference.floats("distance");
  const auto channel = reference.unsigneds("channel");
  const auto type = reference.unsigneds("return_type");
  const auto intensity = reference.unsigneds("intensity");
  const auto time = reference.unsigneds("time_stamp");

  // Our points by (ring, raw distance), with the frame they are in.
  struct Ours {
    const Point* point;
    std::size_t frame;
  };
  std::multimap<std::pair<std::uint32_t, long>, Ours> ours;
  for (std::size_t f = 0; f < r.frames.frames.size(); ++f) {
    for (const Point& p : r.frames.frames[f].points) {
      ours.emplace(std::pair{std::uint32_t{p.ring}, std::lround(static_cast<double>(p.distance_m) / 0.002)},
                   Ours{&p, f});
    }
  }
  const auto nebula_azimuth_deg = [&](std::size_t i) {
    return static_cast<double>(azimuth_rad[i]) * 180.0 / std::numbers::pi;
  };
  const auto azimuth_step = [](double from_deg, double to_deg) {
    double d = to_deg - from_deg;
    if (d > 180.0) d -= 360.0;
    if (d < -180.0) d += 360.0;
    return d;
  };
  // Our point for reference point i in frame `frame` (any frame if none): same ring, raw
  // distance, intensity and return, not yet matched, nearest in azimuth and within 1°
  // (nebula's azimuth can be a whole firing step, 0.4–0.6° here, from the true one).
  std::set<const Point*> used;  // each of our points stands for one reference point
  const auto find = [&](std::size_t i, std::optional<std::size_t> frame) -> const Ours* {
    const Ours* best = nullptr;
    double best_step = 1.0;
    const auto [begin, end] = ours.equal_range({channel[i], std::lround(static_cast<double>(distance[i]) / 0.002)});
    for (auto it = begin; it != end; ++it) {
      const Point& p = *it->second.point;
      if ((frame && it->second.frame != *frame) || p.intensity != intensity[i] ||
          !same_return(type[i], p.return_type) || used.count(&p) != 0) {
        continue;
      }
      const double step = std::abs(azimuth_step(static_cast<double>(p.azimuth_deg), nebula_azimuth_deg(i)));
      if (step <= best_step) {
        best_step = step;
        best = &it->second;
      }
    }
    return best;
  };
  // A static scene repeats every rotation: first find which of our sweeps nebula's is.
  std::map<std::size_t, std::size_t> votes;
  for (std::size_t i = 0; i < reference.points(); ++i) {
    if (const Ours* o = find(i, std::nullopt)) ++votes[o->frame];
  }
  ASSERT_FALSE(votes.empty());
  const std::size_t frame =
      std::max_element(votes.begin(), votes.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;

  // nebula's stamps come from a double of Unix seconds (≈ 240 ns steps): allow 0.5 µs.
  constexpr std::int64_t kTimeTolerance_ns = 500;
  std::optional<std::int64_t> previous_residual;
  std::size_t time_jumps = 0;
  std::size_t direct = 0, turned = 0, missing_points = 0;
  double worst_direct_m = 0.0, worst_turned_m = 0.0, worst_turn_deg = 0.0;
  for (std::size_t i = 0; i < reference.points(); ++i) {
    const Ours* match = find(i, frame);
    if (match == nullptr) {
      if (++missing_points <= 10) {
        ADD_FAILURE() << "nebula point " << i << " (channel " << channel[i] << ", d " << distance[i]
                      << ") has no match";
      }
      continue;
    }
    const Point& p = *match->point;
    used.insert(&p);
    // Time: nebula stamps each point from its packet's receive time and, in dual mode,
    // advances its firing schedule by block (2 × 110.592 µs per firing pair) where the sensor
    // fires once per pair; ours follow the sensor's clock and schedule. Within one firing
    // pair both advance by the same laser and sequence offsets (2.304, 55.296 µs), so the
    // difference is constant there and changes only between pairs and packets.
    const std::int64_t residual = static_cast<std::int64_t>(time[i]) - std::int64_t{p.time_offset_ns};
    if (previous_residual && std::llabs(residual - *previous_residual) > kTimeTolerance_ns) ++time_jumps;
    previous_residual = residual;
    const double turn_deg = azimuth_step(static_cast<double>(p.azimuth_deg), nebula_azimuth_deg(i));
    double px = static_cast<double>(p.x), py = static_cast<double>(p.y);
    const bool interpolated_alike = std::abs(turn_deg) <= 0.0051;  // nebula's 0.01° rounding
    if (!interpolated_alike) {  // turn our point to nebula's azimuth (clockwise from x)
      const double c = std::cos(turn_deg * std::numbers::pi / 180.0), s = std::sin(turn_deg * std::numbers::pi / 180.0);
      px = c * static_cast<double>(p.x) + s * static_cast<double>(p.y);
      py = -s * static_cast<double>(p.x) + c * static_cast<double>(p.y);
      worst_turn_deg = std::max(worst_turn_deg, std::abs(turn_deg));
    }
    const double error = std::max({std::abs(px - static_cast<double>(x[i])), std::abs(py - static_cast<double>(y[i])),
                                   std::abs(static_cast<double>(p.z) - static_cast<double>(z[i]))});
    EXPECT_LE(error, 1e-3) << "nebula point " << i << ", azimuth turned by " << turn_deg << "°";
    if (interpolated_alike) {
      ++direct;
      worst_direct_m = std::max(worst_direct_m, error);
    } else {
      ++turned;
      worst_turned_m = std::max(worst_turned_m, error);
    }
  }
  EXPECT_EQ(missing_points, 0u);
  EXPECT_EQ(direct + turned, reference.points());
  // Most firings nebula interpolates as we do; the others differ by less than one firing's
  // azimuth step.
  EXPECT_GT(direct, reference.points() * 8 / 10);
  // At most one change of the time difference per firing pair (6 a packet) and packet;
  // wrong laser or sequence offsets would change it between nearly every pair of points.
  const std::size_t packets = r.frames.frames[frame].packets;
  EXPECT_LE(time_jumps, packets * 7) << "per-point times not consistent with nebula's";
  EXPECT_LT(time_jumps, reference.points() / 10) << "per-point times not consistent with nebula's";
  RecordProperty("direct_points", std::to_string(direct));
  RecordProperty("turned_points", std::to_string(turned));
  RecordProperty("worst_direct_error_m", std::to_string(worst_direct_m));
  RecordProperty("worst_turned_error_m", std::to_string(worst_turned_m));
  RecordProperty("time_base_changes", std::to_string(time_jumps));
  std::printf(
      "nebula reference: %zu points direct (worst %.2e m), %zu turned by up to %.3f deg (worst %.2e m), "
      "%zu time base changes over %u packets\n",
      direct, worst_direct_m, turned, worst_turn_deg, worst_turned_m, time_jumps, r.frames.frames[frame].packets);
}

// A capture cut inside a record: every whole record before the cut is delivered, then an
// error that says so.
// decode() runs an AVX2 build of the decoder where the processor has AVX2: on real strongest
// and dual captures, with the default calibration and nebula's (rotation corrections, range
// limits), it must give the baseline build's points bit for bit, and its counts.
TEST(Vlp16Capture, TheAvx2DecoderGivesTheBaselinesPointsBitForBit) {
  TRAJROI_REQUIRE_DATA(strongest, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  TRAJROI_REQUIRE_DATA(dual, "velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap");
  TRAJROI_REQUIRE_DATA(yaml, "velodyne/vlp16/nebula_VLP16_calibration.yaml");
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this processor has no AVX2: decode() runs the baseline only";
  DecodeOptions limited;
  limited.min_range_m = 0.3;
  limited.max_range_m = 30.0;
  const PacketDecoder plain(Calibration::vlp16_default());
  const PacketDecoder corrected(parse_calibration_yaml(test::read_file(yaml), yaml.string()), limited);
  for (const auto& path : {strongest, dual}) {
    for (const PacketDecoder* decoder : {&plain, &corrected}) {
      PcapSource source(path);
      Datagram datagram;
      std::vector<Point> baseline, avx2;
      std::size_t packets = 0;
      while (source.next(datagram) == PacketSource::Next::kDatagram) {
        if (validate_data_packet(datagram.payload) != PacketError::kNone) continue;
        ++packets;
        baseline.clear();
        avx2.clear();
        const PacketDecoder::Result a = decoder->decode_baseline(datagram.payload, baseline);
        const PacketDecoder::Result b = decoder->decode_avx2(datagram.payload, avx2);
        ASSERT_EQ(std::tie(a.points, a.no_return, a.out_of_range, a.merged_returns),
                  std::tie(b.points, b.no_return, b.out_of_range, b.merged_returns));
        ASSERT_EQ(baseline.size(), avx2.size());
        for (std::size_t i = 0; i < baseline.size(); ++i) {
          const Point& p = baseline[i];
          const Point& q = avx2[i];
          ASSERT_TRUE(std::memcmp(&p.x, &q.x, 5 * sizeof(float)) == 0 && p.time_offset_ns == q.time_offset_ns &&
                      p.intensity == q.intensity && p.laser == q.laser && p.ring == q.ring &&
                      p.return_type == q.return_type)
              << path << " packet " << packets << " point " << i << ": " << p.x << " " << p.y << " " << p.z
              << " against " << q.x << " " << q.y << " " << q.z;
        }
      }
      EXPECT_GT(packets, 290u) << path;
    }
  }
}

// Frames and counts alike, points bit for bit.
void expect_same_stream(const Replay& a, const Replay& b, const std::string& what) {
  const StreamCounters& x = a.counters;
  const StreamCounters& y = b.counters;
  EXPECT_EQ(std::tie(x.decoded_packets, x.rejected, x.lost_packets, x.points, x.no_return, x.out_of_range,
                     x.merged_returns, x.frames, x.partial_frames),
            std::tie(y.decoded_packets, y.rejected, y.lost_packets, y.points, y.no_return, y.out_of_range,
                     y.merged_returns, y.frames, y.partial_frames))
      << what;
  ASSERT_EQ(a.frames.frames.size(), b.frames.frames.size()) << what;
  for (std::size_t f = 0; f < a.frames.frames.size(); ++f) {
    const Frame& p = a.frames.frames[f];
    const Frame& q = b.frames.frames[f];
    ASSERT_EQ(std::tie(p.index, p.start_time_ns, p.end_time_ns, p.packets, p.lost_packets, p.partial),
              std::tie(q.index, q.start_time_ns, q.end_time_ns, q.packets, q.lost_packets, q.partial))
        << what << " frame " << f;
    ASSERT_EQ(p.points.size(), q.points.size()) << what << " frame " << f;
    static_assert(sizeof(Point) == 28, "Point without padding: compared byte for byte");
    EXPECT_EQ(std::memcmp(p.points.data(), q.points.data(), p.points.size() * sizeof(Point)), 0)
        << what << " frame " << f;
  }
}

// trajroid's input threads decode each data packet ahead with the stream's own decoder
// (StreamDecoder::decoder()); the stream then takes those points instead of decoding: the same
// frames, bit for bit. And it does take them: points decoded ahead with another calibration
// give that calibration's frames.
TEST(Vlp16Capture, PacketsDecodedAheadGiveTheStreamsOwnFrames) {
  TRAJROI_REQUIRE_DATA(strongest, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  TRAJROI_REQUIRE_DATA(dual, "velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap");
  TRAJROI_REQUIRE_DATA(early, "velodyne/vlp16/rust-lidar-utils_velodyne_vlp16_2014_productid0x21.pcap");
  TRAJROI_REQUIRE_DATA(yaml, "velodyne/vlp16/nebula_VLP16_calibration.yaml");
  const Calibration nebula = parse_calibration_yaml(test::read_file(yaml), yaml.string());
  StreamOptions options;
  options.decode.min_range_m = 0.3;
  options.decode.max_range_m = 30.0;
  options.cut_azimuth_deg = 123.45;
  for (const auto& path : {strongest, dual, early}) {
    for (const Calibration& calibration : {Calibration::vlp16_default(), nebula}) {
      const StreamDecoder stream(calibration, options);
      const Replay own = replay(path, calibration, options);
      ASSERT_GT(own.counters.points, 0u) << path;
      expect_same_stream(own, replay(path, calibration, options, &stream.decoder()), path.string());
    }
    // Decoded ahead with nebula's calibration, into a stream set up with the default one (not
    // the early firmware's: its first packet waits for the model check and is decoded then).
    if (path == early) continue;
    const PacketDecoder other(nebula, options.decode);
    const Replay taken = replay(path, Calibration::vlp16_default(), options, &other);
    const Replay reference = replay(path, nebula, options);
    expect_same_stream(taken, reference, path.string() + " (decoded ahead with nebula's calibration)");
  }
}

TEST(Vlp16Capture, TruncatedCaptureDeliversEveryWholeRecordThenAnError) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const std::string bytes = test::read_file(path);
  // Walk the record headers (24-byte file header, 16-byte record headers) to find where the
  // 100th record ends, and cut 500 bytes into the 101st.
  std::size_t at = 24;
  for (int record = 0; record < 100; ++record) {
    std::uint32_t captured = 0;
    std::memcpy(&captured, bytes.data() + at + 8, 4);
    at += 16 + captured;
  }
  const auto cut = std::filesystem::path(testing::TempDir()) / "trajroi_truncated.pcap";
  {
    std::ofstream out(cut, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(at + 500));
  }
  PcapSource source(cut);
  Datagram datagram;
  std::size_t delivered = 0;
  PacketSource::Next next;
  while ((next = source.next(datagram)) == PacketSource::Next::kDatagram)
    ++delivered;
  EXPECT_EQ(delivered, 100u);
  EXPECT_EQ(next, PacketSource::Next::kError);
  EXPECT_NE(source.error().find("truncated"), std::string::npos) << source.error();
  std::filesystem::remove(cut);
}

// A port filter leaves the other datagrams out (pacing is inputs::Pacer's, tested there).
TEST(Vlp16Capture, APortFilterLeavesTheOtherDatagramsOut) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/rust-lidar-utils_velodyne_vlp16_2014_productid0x21.pcap");
  PcapOptions options;
  options.ports = {kDataPort};
  PcapSource source(path, options);
  Datagram datagram;
  std::size_t delivered = 0;
  while (source.next(datagram) == PacketSource::Next::kDatagram) {
    EXPECT_EQ(datagram.destination_port, kDataPort);
    ++delivered;
  }
  EXPECT_EQ(delivered, 84u);
  EXPECT_EQ(source.skipped_records(), 16u);  // the position packets
}

// Every link type the pcap source reads, in captures written here (nanosecond pcap): one
// VLP-16 data packet to port 2368 and one datagram to another port, framed as each link
// layer frames IPv4/UDP.
// (Appends byte by byte: GCC 12 warns falsely on vector::insert of small arrays at -O3.)
std::vector<std::uint8_t> concat(std::vector<std::uint8_t> head, const std::vector<std::uint8_t>& tail) {
  head.reserve(head.size() + tail.size());
  for (const std::uint8_t b : tail)
    head.push_back(b);
  return head;
}

std::vector<std::uint8_t> ipv4_udp(std::uint16_t port, const std::vector<std::uint8_t>& payload) {
  const std::size_t total = 20 + 8 + payload.size();
  const auto hi = [](std::size_t v) { return static_cast<std::uint8_t>(v >> 8); };
  const auto lo = [](std::size_t v) { return static_cast<std::uint8_t>(v); };
  const std::array<std::uint8_t, 28> header = {0x45,
                                               0,
                                               hi(total),
                                               lo(total),
                                               0,
                                               0,
                                               0,
                                               0,
                                               64,
                                               17 /* UDP */,
                                               0,
                                               0,  // IPv4, no checksum
                                               192,
                                               168,
                                               1,
                                               201,
                                               255,
                                               255,
                                               255,
                                               255,  // addresses
                                               hi(port),
                                               lo(port),
                                               hi(port),
                                               lo(port),  // source, destination port
                                               hi(8 + payload.size()),
                                               lo(8 + payload.size()),
                                               0,
                                               0};  // UDP length, no checksum
  return concat({header.begin(), header.end()}, payload);
}

void write_pcap(const std::filesystem::path& path, std::uint32_t link_type,
                const std::vector<std::vector<std::uint8_t>>& frames) {
  std::string bytes;
  const auto put32 = [&](std::uint32_t v) { bytes.append(reinterpret_cast<const char*>(&v), 4); };
  const auto put16 = [&](std::uint16_t v) { bytes.append(reinterpret_cast<const char*>(&v), 2); };
  put32(0xA1B23C4D);  // nanosecond pcap, host (little-endian) order
  put16(2);
  put16(4);
  put32(0);
  put32(0);
  put32(65535);
  put32(link_type);
  std::uint32_t ns = 0;
  for (const auto& frame : frames) {
    put32(1'600'000'000);
    put32(ns += 1'327'000);
    put32(static_cast<std::uint32_t>(frame.size()));
    put32(static_cast<std::uint32_t>(frame.size()));
    bytes.append(reinterpret_cast<const char*>(frame.data()), frame.size());
  }
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(Vlp16Capture, EveryLinkTypeYieldsTheSameDatagram) {
  std::vector<std::uint8_t> payload(kDataPacketBytes);
  for (std::size_t i = 0; i < payload.size(); ++i)
    payload[i] = static_cast<std::uint8_t>(i * 7);
  const auto data = ipv4_udp(kDataPort, payload);
  const auto other = ipv4_udp(5353, std::vector<std::uint8_t>(40, 1));
  const auto ethernet = [](std::vector<std::uint16_t> tags, const std::vector<std::uint8_t>& ip) {
    std::vector<std::uint8_t> f(12, 0xAB);  // destination and source MAC
    for (const std::uint16_t tpid : tags) {
      f = concat(f, {static_cast<std::uint8_t>(tpid >> 8), static_cast<std::uint8_t>(tpid), 0x00, 0x05});
    }
    return concat(concat(f, {0x08, 0x00}), ip);
  };
  const auto sll = [](const std::vector<std::uint8_t>& ip) {
    return concat(concat(std::vector<std::uint8_t>(14, 0), {0x08, 0x00}), ip);  // protocol at 14–15
  };
  const auto sll2 = [](const std::vector<std::uint8_t>& ip) {
    return concat(concat({0x08, 0x00}, std::vector<std::uint8_t>(18, 0)), ip);  // protocol at 0–1, 20 bytes
  };
  struct Case {
    const char* name;
    std::uint32_t link;
    std::vector<std::vector<std::uint8_t>> frames;
  };
  const std::vector<Case> cases = {
      {"ethernet", 1, {ethernet({}, other), ethernet({}, data)}},
      {"802.1Q", 1, {ethernet({0x8100}, other), ethernet({0x8100}, data)}},
      {"QinQ", 1, {ethernet({0x88A8, 0x8100}, other), ethernet({0x88A8, 0x8100}, data)}},
      {"SLL", 113, {sll(other), sll(data)}},
      {"SLL2", 276, {sll2(other), sll2(data)}},
      {"raw IPv4", 101, {other, data}},
      {"IPv4", 228, {other, data}},
  };
  for (const Case& c : cases) {
    const auto path = std::filesystem::path(testing::TempDir()) / "trajroi_link.pcap";
    write_pcap(path, c.link, c.frames);
    PcapSource source(path);
    Datagram datagram;
    ASSERT_EQ(source.next(datagram), PacketSource::Next::kDatagram) << c.name << ": " << source.error();
    EXPECT_EQ(datagram.destination_port, kDataPort) << c.name;
    ASSERT_EQ(datagram.payload.size(), payload.size()) << c.name;
    EXPECT_TRUE(std::equal(payload.begin(), payload.end(), datagram.payload.begin())) << c.name;
    EXPECT_EQ(datagram.receive_time_ns, 1'600'000'000'000'000'000 + 2 * 1'327'000) << c.name;
    EXPECT_EQ(source.next(datagram), PacketSource::Next::kEnd) << c.name;
    EXPECT_EQ(source.skipped_records(), 1u) << c.name;  // port 5353
    std::filesystem::remove(path);
  }
  // A link type it does not read is refused by name.
  const auto path = std::filesystem::path(testing::TempDir()) / "trajroi_link.pcap";
  write_pcap(path, 105, {});  // IEEE 802.11
  EXPECT_THROW(PcapSource{path}, std::runtime_error);
  std::filesystem::remove(path);
}

// What a capture gives, datagram by datagram, and how it ends.
struct Seen {
  std::vector<std::uint8_t> bytes;
  std::vector<std::int64_t> times;
  std::vector<std::uint16_t> ports;
  PacketSource::Next end = PacketSource::Next::kDatagram;
  std::uint64_t skipped = 0;
  std::string error;
};

Seen read_capture(const std::filesystem::path& from) {
  Seen seen;
  PcapSource source(from);
  Datagram datagram;
  while ((seen.end = source.next(datagram)) == PacketSource::Next::kDatagram) {
    seen.bytes.insert(seen.bytes.end(), datagram.payload.begin(), datagram.payload.end());
    seen.times.push_back(datagram.receive_time_ns);
    seen.ports.push_back(datagram.destination_port);
  }
  seen.skipped = source.skipped_records();
  seen.error = source.error();
  return seen;
}

// `bytes` as a regular file (mapped: a classic pcap file is read in place by trajroi) and
// through a pipe (read as a stream by libpcap), which must agree datagram for datagram.
void expect_read_in_place_as_libpcap_reads(const std::string& bytes, const std::string& what) {
  const auto file = std::filesystem::path(testing::TempDir()) / "trajroi_capture.pcap";
  const auto fifo = std::filesystem::path(testing::TempDir()) / "trajroi_capture.fifo";
  {
    std::ofstream out(file, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  const Seen mapped = read_capture(file);
  // A reader that stops at an error closes the pipe on a writer with bytes left: EPIPE, not
  // the end of the test process.
  struct sigaction ignore {};
  struct sigaction before {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &ignore, &before);
  std::filesystem::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
  const Seen streamed = read_capture(fifo);
  writer.join();
  sigaction(SIGPIPE, &before, nullptr);
  std::filesystem::remove(fifo);
  std::filesystem::remove(file);
  EXPECT_EQ(mapped.times.size(), streamed.times.size()) << what;
  EXPECT_EQ(mapped.times, streamed.times) << what;
  EXPECT_EQ(mapped.ports, streamed.ports) << what;
  EXPECT_TRUE(mapped.bytes == streamed.bytes) << what;
  EXPECT_EQ(mapped.end, streamed.end) << what << ": in place '" << mapped.error << "', libpcap '" << streamed.error
                                      << "'";
  EXPECT_EQ(mapped.skipped, streamed.skipped) << what;
  if (streamed.error.find("truncated") != std::string::npos) {
    EXPECT_NE(mapped.error.find("truncated"), std::string::npos) << what << ": " << mapped.error;
  }
}

std::uint32_t get32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}
void put32(std::string& b, std::size_t at, std::uint32_t v) {
  std::memcpy(b.data() + at, &v, 4);
}
void put16(std::string& b, std::size_t at, std::uint16_t v) {
  std::memcpy(b.data() + at, &v, 2);
}

// Offsets of the record headers of a little-endian classic pcap file.
std::vector<std::size_t> record_offsets(const std::string& b) {
  std::vector<std::size_t> at;
  for (std::size_t i = 24; i + 16 <= b.size(); i += 16 + get32(b, i + 8))
    at.push_back(i);
  return at;
}

// Every capture of the data folder, and variants of one made for the cases libpcap knows: time
// stamps in ns, the other byte order, a snap length shorter than the records, a file cut in a
// record header and in a record, a record longer than libpcap allows, and a file that is not a
// capture.
TEST(Vlp16Capture, ClassicCapturesAreReadInPlaceAsLibpcapReadsThem) {
  TRAJROI_REQUIRE_DATA(mrpt, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(test::data_dir() / "velodyne")) {
    if (entry.path().extension() != ".pcap") continue;
    expect_read_in_place_as_libpcap_reads(test::read_file(entry.path()), entry.path().filename().string());
    ++files;
  }
  EXPECT_GE(files, 7u);

  const std::string original = test::read_file(mrpt);
  ASSERT_EQ(get32(original, 0), 0xA1B2C3D4u);  // little-endian, µs
  const std::vector<std::size_t> records = record_offsets(original);
  ASSERT_GT(records.size(), 200u);

  std::string nanoseconds = original;
  put32(nanoseconds, 0, 0xA1B23C4D);
  expect_read_in_place_as_libpcap_reads(nanoseconds, "ns time stamps");

  std::string big_endian = original;
  const auto swap_field = [&big_endian](std::size_t at) {
    put32(big_endian, at, __builtin_bswap32(get32(big_endian, at)));
  };
  for (std::size_t at : {0u, 8u, 12u, 16u, 20u})
    swap_field(at);
  put16(big_endian, 4, __builtin_bswap16(2));
  put16(big_endian, 6, __builtin_bswap16(4));
  for (std::size_t r : records) {
    for (std::size_t field = 0; field < 16; field += 4)
      swap_field(r + field);
  }
  expect_read_in_place_as_libpcap_reads(big_endian, "big-endian");

  std::string short_snap = original;
  put32(short_snap, 16, 600);  // shorter than a data packet's frame: those are cut and skipped
  expect_read_in_place_as_libpcap_reads(short_snap, "snap length 600");

  expect_read_in_place_as_libpcap_reads(original.substr(0, records[150] + 9), "cut in a record header");
  expect_read_in_place_as_libpcap_reads(original.substr(0, records[150] + 16 + 700), "cut in a record");

  std::string oversized = original;
  put32(oversized, records[40] + 8, 300'000);
  expect_read_in_place_as_libpcap_reads(oversized, "a record over 262 144 bytes");

  const auto not_capture = std::filesystem::path(testing::TempDir()) / "trajroi_not_capture.pcap";
  {
    std::ofstream out(not_capture, std::ios::binary);
    out << "this is not a capture file, only text long enough to have a header";
  }
  EXPECT_THROW(PcapSource{not_capture}, std::runtime_error);
  std::filesystem::remove(not_capture);
  const auto empty = std::filesystem::path(testing::TempDir()) / "trajroi_empty.pcap";
  { std::ofstream out(empty, std::ios::binary); }
  EXPECT_THROW(PcapSource{empty}, std::runtime_error);
  std::filesystem::remove(empty);
}

// A capture another program truncates while it is replayed (its pages past the new end gone
// from the mapping): a read error that says so, not a SIGBUS that ends the process; the thread
// stays able to do it again, and a capture read afterwards reads as before.
TEST(Vlp16Capture, ACaptureTruncatedWhileItIsReadIsAReadErrorNotACrash) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const std::string bytes = test::read_file(path);
  ASSERT_GT(bytes.size(), 64u * 1024u);
  const auto copy = std::filesystem::path(testing::TempDir()) / "trajroi_shrinking.pcap";
  for (int round = 0; round < 2; ++round) {
    {
      std::ofstream out(copy, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
    PcapSource source(copy);
    Datagram datagram;
    for (int k = 0; k < 5; ++k)
      ASSERT_EQ(source.next(datagram), PacketSource::Next::kDatagram) << source.error();
    std::filesystem::resize_file(copy, 16 * 1024);  // a page boundary past what was read
    std::size_t more = 0;
    PacketSource::Next next;
    while ((next = source.next(datagram)) == PacketSource::Next::kDatagram)
      ++more;
    EXPECT_EQ(next, PacketSource::Next::kError) << "round " << round;
    EXPECT_NE(source.error().find("shrank"), std::string::npos) << source.error();
    EXPECT_LT(more, 20u);
  }
  std::filesystem::remove(copy);
  const Seen after = read_capture(path);
  EXPECT_EQ(after.end, PacketSource::Next::kEnd) << after.error;
  EXPECT_GT(after.times.size(), 100u);
}

TEST(Vlp16Capture, UnreadableFileIsAClearError) {
  try {
    PcapSource source("/nonexistent/capture.pcap");
    FAIL() << "opened a missing file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/capture.pcap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace trajroi::vlp16
