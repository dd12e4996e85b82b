// Real captures decoded against references other than the stream's counts: nebula's reference
// cloud of a dual-return sweep point for point, the AVX2 build of the decoder against the
// baseline's bit for bit, and points decoded ahead (as trajroid's input threads do) against the
// stream's own decoding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "capture_replay.hpp"
#include "pcd_reader.hpp"
#include "test_data.hpp"
#include "trajroi/vlp16/decoder.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16 {
namespace {

using capture_test::Replay;
using capture_test::replay;

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

}  // namespace
}  // namespace trajroi::vlp16
