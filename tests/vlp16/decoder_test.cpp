// VLP-16 data packets built byte by byte in the test; expected values from the VLP-16
// manual's formulas, written out here independently of the decoder.
#include "trajroi/vlp16/decoder.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "packet_builder.hpp"
#include "test_data.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(Vlp16Packet, AccessorsReadLittleEndianFields) {
  auto p = make_packet(1000, 40, ReturnMode::kStrongest, 0x22, 0x01020304);
  set_return(p, 5, 31, 0xABCD, 9);
  EXPECT_EQ(validate_data_packet(p), PacketError::kNone);
  EXPECT_EQ(block_azimuth(p, 5), 1200);
  EXPECT_EQ(channel_distance(p, 5, 31), 0xABCD);
  EXPECT_EQ(channel_reflectivity(p, 5, 31), 9);
  EXPECT_EQ(timestamp_us(p), 0x01020304u);
}

TEST(Vlp16Packet, EveryRejectionReason) {
  auto good = make_packet(0, 40, ReturnMode::kStrongest);
  EXPECT_EQ(validate_data_packet(std::span(good).first(1205)), PacketError::kWrongSize);
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_EQ(validate_data_packet(longer), PacketError::kWrongSize);
  auto flag = good;
  flag[700] = 0xFE;  // block 7's flag
  EXPECT_EQ(validate_data_packet(flag), PacketError::kBadBlockFlag);
  auto azimuth = good;
  azimuth[302] = 0x40;  // block 3 azimuth 0x9C40 = 40000
  azimuth[303] = 0x9C;
  EXPECT_EQ(validate_data_packet(azimuth), PacketError::kAzimuthOutOfRange);
  auto mode = good;
  mode[1204] = 0x3A;
  EXPECT_EQ(validate_data_packet(mode), PacketError::kUnknownReturnMode);
  const auto vls128 = make_packet(0, 40, ReturnMode::kStrongest, 0xA1);
  EXPECT_EQ(validate_data_packet(vls128), PacketError::kUnsupportedProduct);
  EXPECT_EQ(product_name(0xA1), "VLS-128");
  for (const std::uint8_t id : {kProductHdl32e, kProductVlp16, kProductPuckHiRes, kProductVlp32c})  // decoded
    EXPECT_EQ(validate_data_packet(make_packet(0, 40, ReturnMode::kStrongest, id)), PacketError::kNone) << int{id};
  // 0x21 passes validation: whether it is an early VLP-16 is decided from the timing.
  EXPECT_EQ(validate_data_packet(make_packet(0, 40, ReturnMode::kStrongest, 0x21)), PacketError::kNone);
  EXPECT_EQ(to_string(PacketError::kBadBlockFlag), "bad_block_flag");
}

TEST(Vlp16Decoder, StrongestModeGeometryAndTimingFollowTheManual) {
  auto p = make_packet(1000, 40, ReturnMode::kStrongest);
  set_return(p, 0, 0, 5000, 77);   // block 0, firing 0, laser 0 (−15°): 10 m
  set_return(p, 3, 17, 2500, 12);  // block 3, firing 1, laser 1 (+1°): 5 m
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  const PacketDecoder::Result r = decoder.decode(p, points);
  ASSERT_EQ(r.points, 2u);
  EXPECT_EQ(r.no_return, 12u * 32u - 2u);

  // Manual: x_m = R cos ω sin α, y_m = R cos ω cos α (y forward); REP-103: x = y_m, y = −x_m.
  // The laser's vertical offset v moves the origin along the beam's normal (velodyne model):
  // r_xy = R cos ω − v sin ω, z = R sin ω + v cos ω.
  const Point& a = points[0];
  const double alpha_a = 10.0 * kDeg;
  const double r_xy_a = 10.0 * std::cos(-15 * kDeg) - 0.0112 * std::sin(-15 * kDeg);
  EXPECT_NEAR(a.x, r_xy_a * std::cos(alpha_a), 1e-5);
  EXPECT_NEAR(a.y, -r_xy_a * std::sin(alpha_a), 1e-5);
  EXPECT_NEAR(a.z, 10.0 * std::sin(-15 * kDeg) + 0.0112 * std::cos(-15 * kDeg), 1e-5);
  EXPECT_EQ(a.ring, 0);  // −15°: the lowest
  EXPECT_EQ(a.time_offset_ns, 0u);
  EXPECT_EQ(a.intensity, 77);
  EXPECT_EQ(a.laser, 0);
  EXPECT_EQ(a.return_type, ReturnType::kStrongest);
  EXPECT_FLOAT_EQ(a.distance_m, 10.0f);

  // Block 3, second firing, laser 1: t = 3 · 110.592 + 55.296 + 2.304 µs; the azimuth moves
  // 0.40° per block, so by (55.296 + 2.304) / 110.592 of it.
  const Point& b = points[1];
  const double t_us = 3 * 110.592 + 55.296 + 2.304;
  EXPECT_EQ(b.time_offset_ns, static_cast<std::uint32_t>(std::lround(t_us * 1000)));
  const double alpha_b_deg = 11.2 + 0.4 * (55.296 + 2.304) / 110.592;
  EXPECT_NEAR(b.azimuth_deg, alpha_b_deg, 1e-4);
  const double r_xy_b = 5.0 * std::cos(1 * kDeg) + 0.0007 * std::sin(1 * kDeg);
  EXPECT_NEAR(b.x, r_xy_b * std::cos(alpha_b_deg * kDeg), 1e-5);
  EXPECT_NEAR(b.y, -r_xy_b * std::sin(alpha_b_deg * kDeg), 1e-5);
  EXPECT_NEAR(b.z, 5.0 * std::sin(1 * kDeg) - 0.0007 * std::cos(1 * kDeg), 1e-5);
  EXPECT_EQ(b.laser, 1);
  EXPECT_EQ(b.ring, 8);  // +1°: above the eight lasers −15 … −1°
}

TEST(Vlp16Decoder, AzimuthWrapsInsideAPacketAndLastBlockUsesThePreviousGap) {
  auto p = make_packet(35900, 40, ReturnMode::kStrongest);  // blocks: 359.00, 359.40, 359.80, 0.20 …
  set_return(p, 2, 16, 1000, 1);   // block 2 (359.80°), second firing: + 0.20° → 360.00 → 0.00
  set_return(p, 11, 16, 1000, 1);  // last block: gap taken from blocks 10 → 11
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  decoder.decode(p, points);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_NEAR(points[0].azimuth_deg, 0.0, 1e-4);
  EXPECT_NEAR(points[0].y, 0.0, 1e-5);  // straight ahead
  EXPECT_NEAR(points[1].azimuth_deg, (35900 + 40 * 11) % 36000 / 100.0 + 0.2, 1e-4);
}

// Centidegrees become degrees by a division by 100 (the manual's interpolated azimuth, in
// float). Where the series covers the gap, the decoder multiplies by 0.01 instead: for that
// to change nothing, the two must give the same float for every azimuth, gap and channel.
// All 577 million, one by one.
TEST(Vlp16Decoder, AzimuthTimesAHundredthIsTheDivisionInFloat) {
  std::array<double, kFiringsPerBlock * kLasers> fraction{};
  for (std::size_t channel = 0; channel < fraction.size(); ++channel)
    fraction[channel] = azimuth_fraction(channel);
  std::size_t differ = 0;
  for (std::uint32_t azimuth = 0; azimuth < kAzimuthLimit; ++azimuth) {
    for (std::uint32_t gap = 0; gap <= kSeriesGapLimit_cdeg; ++gap) {
      for (const double f : fraction) {
        double cdeg = static_cast<double>(azimuth) + static_cast<double>(gap) * f;
        if (cdeg >= kAzimuthLimit) cdeg -= kAzimuthLimit;
        if (static_cast<float>(cdeg * 0.01) != static_cast<float>(cdeg / 100.0)) ++differ;
      }
    }
  }
  EXPECT_EQ(differ, 0u);
}

// And the decoder's azimuths, on both sides of the limit, are the manual's interpolation
// divided by 100: blocks at a spread of azimuths, every channel returning.
TEST(Vlp16Decoder, EveryChannelsAzimuthIsTheInterpolationInDegrees) {
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  std::size_t checked = 0;
  for (std::uint16_t gap = 0; gap <= 600; gap += 7) {
    for (std::uint16_t first = 0; first < 36000; first += 997) {
      auto p = make_packet(first, gap, ReturnMode::kStrongest);
      for (std::size_t block = 0; block < kBlocks; ++block)
        for (std::size_t channel = 0; channel < kFiringsPerBlock * kLasers; ++channel)
          set_return(p, block, channel, 5000, 10);
      points.clear();
      decoder.decode(p, points);
      ASSERT_EQ(points.size(), kBlocks * kFiringsPerBlock * kLasers);
      for (std::size_t i = 0; i < points.size(); ++i) {
        const std::size_t block = i / (kFiringsPerBlock * kLasers);
        const std::size_t channel = i % (kFiringsPerBlock * kLasers);
        double cdeg =
            static_cast<double>((first + gap * block) % 36000) + static_cast<double>(gap) * azimuth_fraction(channel);
        if (cdeg >= kAzimuthLimit) cdeg -= kAzimuthLimit;
        float expected = static_cast<float>(cdeg / 100.0);
        if (!(expected < 360.0f)) expected = 0.0f;
        ASSERT_EQ(points[i].azimuth_deg, expected)
            << "first " << first << " gap " << gap << " block " << block << " channel " << channel;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1'000'000u);
}

// decode() runs the build the start-up timing chose: TRAJROI_SIMD forces one without timing;
// else, where the processor has AVX2, both are timed and the AVX2 build is taken unless the
// baseline is at least 3 % faster.
TEST(Vlp16Decoder, TheDecoderBuildIsTimedOrForced) {
  const bool avx2 = __builtin_cpu_supports("avx2");
  for (const char* path : {"scalar", "sse2"}) {
    const DecoderCalibration c = calibrate_decoder(path);
    EXPECT_TRUE(c.forced) << path;
    EXPECT_EQ(c.chosen, DecoderBuild::kBaseline) << path;
    EXPECT_EQ(describe(c), "baseline (forced by TRAJROI_SIMD)");
  }
  for (const char* path : {"avx2", "avx512"}) {
    const DecoderCalibration c = calibrate_decoder(path);
    EXPECT_TRUE(c.forced) << path;
    EXPECT_EQ(c.chosen, avx2 ? DecoderBuild::kAvx2 : DecoderBuild::kBaseline) << path;
  }
  for (const char* path : {static_cast<const char*>(nullptr), "", "auto"}) {
    const DecoderCalibration c = calibrate_decoder(path);
    EXPECT_FALSE(c.forced);
    EXPECT_EQ(c.avx2_available, avx2);
    if (!avx2) {
      EXPECT_EQ(c.chosen, DecoderBuild::kBaseline);
      EXPECT_EQ(describe(c), "baseline (no AVX2)");
      continue;
    }
    EXPECT_GT(c.baseline_ns_per_point, 0.0);
    EXPECT_GT(c.avx2_ns_per_point, 0.0);
    EXPECT_EQ(c.chosen,
              c.baseline_ns_per_point < 0.97 * c.avx2_ns_per_point ? DecoderBuild::kBaseline : DecoderBuild::kAvx2);
    EXPECT_NE(describe(c).find(std::string(to_string(c.chosen)) + " (avx2 "), std::string::npos) << describe(c);
  }
}

TEST(Vlp16Decoder, LastReturnModeAndRangeLimits) {
  auto p = make_packet(0, 40, ReturnMode::kLast);
  set_return(p, 0, 0, 100, 1);    // 0.2 m
  set_return(p, 0, 1, 1000, 1);   // 2 m
  set_return(p, 0, 2, 60000, 1);  // 120 m
  DecodeOptions options;
  options.min_range_m = 0.3;
  options.max_range_m = 100.0;
  const PacketDecoder decoder(Calibration::vlp16_default(), options);
  std::vector<Point> points;
  const PacketDecoder::Result r = decoder.decode(p, points);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(r.out_of_range, 2u);
  EXPECT_EQ(points[0].return_type, ReturnType::kLast);
  EXPECT_EQ(points[0].laser, 1);
}

TEST(Vlp16Decoder, DualReturnPairsShareTheFiringAndIdenticalReturnsGiveOnePoint) {
  auto p = make_packet(2000, 40, ReturnMode::kDual);  // pairs (0,1), (2,3), …: 0.40° per pair
  set_return(p, 0, 3, 1500, 10);                      // last
  set_return(p, 1, 3, 1500, 10);                      // strongest, identical → one point
  set_return(p, 2, 4, 2000, 20);                      // last
  set_return(p, 3, 4, 1800, 90);                      // strongest, different → two points
  set_return(p, 5, 6, 700, 50);                       // only the strongest block has a return
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  decoder.decode(p, points);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[0].return_type, ReturnType::kBoth);
  EXPECT_FLOAT_EQ(points[0].distance_m, 3.0f);
  EXPECT_EQ(points[1].return_type, ReturnType::kLast);
  EXPECT_EQ(points[2].return_type, ReturnType::kStrongest);
  EXPECT_EQ(points[1].time_offset_ns, points[2].time_offset_ns);  // one firing
  EXPECT_EQ(points[1].azimuth_deg, points[2].azimuth_deg);
  // pair 1 is the packet's second firing pair: 110.592 µs after pair 0
  EXPECT_EQ(points[1].time_offset_ns, static_cast<std::uint32_t>(std::lround((110.592 + 4 * 2.304) * 1000)));
  EXPECT_EQ(points[3].return_type, ReturnType::kStrongest);
  EXPECT_EQ(points[3].intensity, 50);
  EXPECT_EQ(points[3].time_offset_ns, static_cast<std::uint32_t>(std::lround((2 * 110.592 + 6 * 2.304) * 1000)));
}

}  // namespace
}  // namespace trajroi::vlp16

namespace trajroi::vlp16 {
namespace {

constexpr const char* kTwoLasers = R"(lasers:
  - {dist_correction: 0.01, laser_id: 1, rot_correction: 0.002, vert_correction: 0.0174532925, vert_offset_correction: -0.0007, horiz_offset_correction: 0.001}
  - {laser_id: 0, vert_correction: -0.261799388}
)";

std::string sixteen_lasers(const std::string& replace_laser_7 = "") {
  std::string yaml = "lasers:\n";
  for (int i = 0; i < 16; ++i) {
    yaml += i == 7 && !replace_laser_7.empty()
                ? replace_laser_7
                : "  - {laser_id: " + std::to_string(i) +
                      ", vert_correction: " + std::to_string((i % 2 ? 1 : -1) * 0.01 * i) + ", rot_correction: 0.0}\n";
  }
  return yaml;
}

TEST(Vlp16Calibration, YamlFieldsAreReadByLaserId) {
  const Calibration c =
      parse_calibration_yaml(sixteen_lasers("  - {laser_id: 7, vert_correction: 0.12, rot_correction: "
                                            "-0.001, vert_offset_correction: 0.005, "
                                            "horiz_offset_correction: 0.002, dist_correction: 0.03}\n"),
                             "cal.yaml");
  EXPECT_DOUBLE_EQ(c.lasers[7].vert_angle_rad, 0.12);
  EXPECT_DOUBLE_EQ(c.lasers[7].rot_correction_rad, -0.001);
  EXPECT_DOUBLE_EQ(c.lasers[7].vert_offset_m, 0.005);
  EXPECT_DOUBLE_EQ(c.lasers[7].horiz_offset_m, 0.002);
  EXPECT_DOUBLE_EQ(c.lasers[7].dist_correction_m, 0.03);
  EXPECT_DOUBLE_EQ(c.lasers[6].vert_angle_rad, -0.06);
}

TEST(Vlp16Calibration, NebulaFileMatchesTheManualAngles) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/nebula_VLP16_calibration.yaml");
  const Calibration c = parse_calibration_yaml(test::read_file(path), path.string());
  const Calibration manual = Calibration::vlp16_default();
  for (std::size_t i = 0; i < kLasers; ++i) {
    EXPECT_NEAR(c.lasers[i].vert_angle_rad, manual.lasers[i].vert_angle_rad, 1e-12) << i;
    EXPECT_EQ(c.lasers[i].vert_offset_m, 0.0);
  }
  // Rings by elevation: −15° … −1° are the even lasers, +1° … +15° the odd ones.
  const auto rings = c.rings();
  for (std::size_t i = 0; i < kLasers; ++i)
    EXPECT_EQ(rings[i], i % 2 == 0 ? i / 2 : 8 + i / 2) << i;
}

TEST(Vlp16Calibration, BadFilesNameTheProblem) {
  const auto message = [](const std::string& yaml) {
    try {
      (void)parse_calibration_yaml(yaml, "cal.yaml");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(message(kTwoLasers),
            "cal.yaml:2: 'lasers' has 2 entries; the models trajroi decodes have 16 (VLP-16, Puck LITE, Puck Hi-Res) "
            "or 32 (VLP-32C, HDL-32E)");
  EXPECT_EQ(message("foo: 1\n"), "cal.yaml: no 'lasers' list");
  EXPECT_NE(message("lasers: [\n").find("cal.yaml: line"), std::string::npos);
  EXPECT_EQ(message(sixteen_lasers("  - {laser_id: 3, vert_correction: 0.1}\n")),
            "cal.yaml:9: laser_id 3 appears twice");
  EXPECT_EQ(message(sixteen_lasers("  - {laser_id: 7}\n")), "cal.yaml:9: laser entry 7 has no 'vert_correction'");
  EXPECT_EQ(message(sixteen_lasers("  - {laser_id: 7, vert_correction: abc}\n")),
            "cal.yaml:9: laser entry 7: 'vert_correction' is not a number");
  EXPECT_EQ(message(sixteen_lasers("  - {laser_id: 16, vert_correction: 0.1}\n")),
            "cal.yaml:9: laser entry 7: laser_id 16.000000 is not 0 … 15");
  EXPECT_EQ(message(sixteen_lasers("  - {laser_id: 7, vert_correction: 15}\n")),
            "cal.yaml:9: laser_id 7: vert_correction is not an angle in radians");
}

// Corrections follow the velodyne model: θ = azimuth − rot_correction, range + dist_correction,
// horizontal offset across the beam.
TEST(Vlp16Calibration, CorrectionsEnterTheGeometry) {
  Calibration c = Calibration::vlp16_default();
  c.lasers[2] = LaserCalibration{0.1, 0.05, 0.0, 0.02, 0.3};
  auto p = make_packet(9000, 40, ReturnMode::kStrongest);
  set_return(p, 0, 2, 5000, 1);  // 10 m, azimuth 90° + 2 × 2.304 / 110.592 × 0.4°
  std::vector<Point> points;
  PacketDecoder(c).decode(p, points);
  ASSERT_EQ(points.size(), 1u);
  const double range = 10.3;
  const double theta = (90.0 + 0.4 * 2 * 2.304 / 110.592) * std::numbers::pi / 180.0 - 0.05;
  const double r_xy = range * std::cos(0.1);
  EXPECT_NEAR(points[0].x, r_xy * std::cos(theta) + 0.02 * std::sin(theta), 1e-5);
  EXPECT_NEAR(points[0].y, -r_xy * std::sin(theta) + 0.02 * std::cos(theta), 1e-5);
  EXPECT_NEAR(points[0].z, range * std::sin(0.1), 1e-5);
  EXPECT_FLOAT_EQ(points[0].distance_m, 10.3f);
}

// Random bytes with valid framing: whatever the distances and azimuths, the decoder stays in
// bounds and accounts for every return (run under ASan/UBSan by the test script).
TEST(Vlp16Decoder, RandomPacketsAreDecodedWithinBoundsAndFullyAccounted) {
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  const auto random_byte = [&] {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return static_cast<std::uint8_t>(state);
  };
  const PacketDecoder decoder(Calibration::vlp16_default(), DecodeOptions{0.5, 100.0});
  std::vector<Point> points;
  for (int n = 0; n < 2000; ++n) {
    std::vector<std::uint8_t> p(kDataPacketBytes);
    for (auto& b : p)
      b = random_byte();
    for (std::size_t block = 0; block < kBlocks; ++block) {
      p[block * 100] = 0xFF;
      p[block * 100 + 1] = 0xEE;
      p[block * 100 + 3] = static_cast<std::uint8_t>(p[block * 100 + 3] % 0x8C);  // azimuth < 35840
    }
    p[1204] = static_cast<std::uint8_t>(0x37 + n % 3);
    p[1205] = 0x22;
    ASSERT_EQ(validate_data_packet(p), PacketError::kNone);
    points.clear();
    const PacketDecoder::Result r = decoder.decode(p, points);
    EXPECT_EQ(r.points + r.no_return + r.out_of_range + r.merged_returns, 384u);
    for (const Point& point : points) {
      ASSERT_TRUE(std::isfinite(point.x) && std::isfinite(point.y) && std::isfinite(point.z));
      ASSERT_GE(point.azimuth_deg, 0.0f);
      ASSERT_LT(point.azimuth_deg, 360.0f);
      ASSERT_LE(point.distance_m, 100.0f);
    }
  }
}

}  // namespace
}  // namespace trajroi::vlp16
