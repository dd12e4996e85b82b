// The VLP-16 encoders against the decoders (random round trips) and against the test's own
// byte-by-byte packet builder (the layout, independently of both).
#include "trajroi/vlp16/encoder.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "packet_builder.hpp"
#include "trajroi/vlp16/decoder.hpp"

namespace trajroi::vlp16 {
namespace {

using Packet = std::array<std::uint8_t, kDataPacketBytes>;

std::vector<FiringBlock> random_blocks(std::mt19937& rng, ReturnMode mode) {
  std::uniform_int_distribution<int> azimuth(0, 35999);
  std::uniform_int_distribution<int> step(15, 45);
  std::uniform_int_distribution<int> distance(0, 65535);
  std::uniform_int_distribution<int> byte(0, 255);
  std::bernoulli_distribution missing(0.2);
  std::bernoulli_distribution same(0.3);
  std::vector<FiringBlock> blocks(firing_blocks_per_packet(mode));
  int az = azimuth(rng);
  for (FiringBlock& block : blocks) {
    block.azimuth_cdeg = static_cast<std::uint16_t>(az % 36000);
    az += step(rng);
    for (std::size_t ch = 0; ch < kChannelsPerBlock; ++ch) {
      block.strongest[ch] = {static_cast<std::uint16_t>(missing(rng) ? 0 : distance(rng)),
                             static_cast<std::uint8_t>(byte(rng))};
      block.last[ch] = same(rng) ? block.strongest[ch]
                                 : Echo{static_cast<std::uint16_t>(missing(rng) ? 0 : distance(rng)),
                                        static_cast<std::uint8_t>(byte(rng))};
    }
  }
  return blocks;
}

// What the decoder must give back, in its order: firing by firing, channel by channel, the
// last return then the strongest (dual), identical returns merged.
struct Expected {
  std::uint16_t distance_2mm;
  std::uint8_t reflectivity;
  std::size_t block;
  std::size_t channel;
  ReturnType type;
};

std::vector<Expected> expected_points(ReturnMode mode, const std::vector<FiringBlock>& blocks) {
  std::vector<Expected> out;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (std::size_t ch = 0; ch < kChannelsPerBlock; ++ch) {
      const Echo& s = blocks[b].strongest[ch];
      const Echo& l = blocks[b].last[ch];
      if (mode == ReturnMode::kStrongest) {
        if (s.distance_2mm != 0) out.push_back({s.distance_2mm, s.reflectivity, b, ch, ReturnType::kStrongest});
      } else if (mode == ReturnMode::kLast) {
        if (l.distance_2mm != 0) out.push_back({l.distance_2mm, l.reflectivity, b, ch, ReturnType::kLast});
      } else if (s.distance_2mm == l.distance_2mm) {
        if (l.distance_2mm != 0) out.push_back({l.distance_2mm, l.reflectivity, b, ch, ReturnType::kBoth});
      } else {
        if (l.distance_2mm != 0) out.push_back({l.distance_2mm, l.reflectivity, b, ch, ReturnType::kLast});
        if (s.distance_2mm != 0) out.push_back({s.distance_2mm, s.reflectivity, b, ch, ReturnType::kStrongest});
      }
    }
  }
  return out;
}

class EncoderRoundTrip : public ::testing::TestWithParam<ReturnMode> {};

TEST_P(EncoderRoundTrip, RandomPacketsDecodeToTheEncodedReturns) {
  const ReturnMode mode = GetParam();
  std::mt19937 rng(static_cast<unsigned>(mode) * 7919u);
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  for (int trial = 0; trial < 200; ++trial) {
    const auto blocks = random_blocks(rng, mode);
    const auto toh = static_cast<std::uint32_t>(rng() % 3'600'000'000u);
    Packet packet{};
    encode_data_packet({mode, kProductVlp16, toh}, blocks, packet);
    ASSERT_EQ(validate_data_packet(packet), PacketError::kNone);
    EXPECT_EQ(timestamp_us(packet), toh);
    EXPECT_EQ(return_mode_byte(packet), static_cast<std::uint8_t>(mode));
    points.clear();
    decoder.decode(packet, points);
    const auto expected = expected_points(mode, blocks);
    ASSERT_EQ(points.size(), expected.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Expected& e = expected[i];
      const Point& p = points[i];
      ASSERT_EQ(p.distance_m, static_cast<float>(e.distance_2mm * 0.002)) << i;
      ASSERT_EQ(p.intensity, e.reflectivity) << i;
      ASSERT_EQ(p.laser, e.channel % kLasers) << i;
      ASSERT_EQ(p.return_type, e.type) << i;
      // The manual's timing: firing pair × 110.592 + sequence × 55.296 + laser × 2.304 µs.
      const double t_us = static_cast<double>(e.block) * 110.592 + static_cast<double>(e.channel / kLasers) * 55.296 +
                          static_cast<double>(e.channel % kLasers) * 2.304;
      ASSERT_EQ(p.time_offset_ns, static_cast<std::uint32_t>(std::lround(t_us * 1000.0))) << i;
      if (e.channel == 0) {
        ASSERT_FLOAT_EQ(p.azimuth_deg, static_cast<float>(blocks[e.block].azimuth_cdeg / 100.0));
      }
    }
  }
}

TEST_P(EncoderRoundTrip, BytesMatchTheTestBuilderLayout) {
  const ReturnMode mode = GetParam();
  std::mt19937 rng(42);
  auto blocks = random_blocks(rng, mode);
  for (std::size_t i = 0; i < blocks.size(); ++i)
    blocks[i].azimuth_cdeg = static_cast<std::uint16_t>((35990 + 40 * i) % 36000);
  Packet packet{};
  encode_data_packet({mode, kProductVlp16, 987654}, blocks, packet);
  auto built = make_packet(35990, 40, mode, 0x22, 987654);
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    for (std::size_t ch = 0; ch < kChannelsPerBlock; ++ch) {
      const Echo& s = blocks[i].strongest[ch];
      const Echo& l = blocks[i].last[ch];
      if (mode == ReturnMode::kDual) {
        set_return(built, 2 * i, ch, l.distance_2mm, l.reflectivity);
        set_return(built, 2 * i + 1, ch, s.distance_2mm, s.reflectivity);
      } else {
        const Echo& e = mode == ReturnMode::kLast ? l : s;
        set_return(built, i, ch, e.distance_2mm, e.reflectivity);
      }
    }
  }
  EXPECT_TRUE(std::equal(packet.begin(), packet.end(), built.begin(), built.end()));
}

INSTANTIATE_TEST_SUITE_P(Modes, EncoderRoundTrip,
                         ::testing::Values(ReturnMode::kStrongest, ReturnMode::kLast, ReturnMode::kDual),
                         [](const ::testing::TestParamInfo<ReturnMode>& mode) {
                           return std::string(mode.param == ReturnMode::kStrongest ? "Strongest"
                                              : mode.param == ReturnMode::kLast    ? "Last"
                                                                                   : "Dual");
                         });

TEST(Vlp16Encoder, RejectsWhatNoSensorSends) {
  Packet packet{};
  std::vector<FiringBlock> six(6), twelve(12);
  EXPECT_THROW(encode_data_packet({ReturnMode::kStrongest, kProductVlp16, 0}, six, packet), std::invalid_argument);
  EXPECT_THROW(encode_data_packet({ReturnMode::kDual, kProductVlp16, 0}, twelve, packet), std::invalid_argument);
  EXPECT_THROW(encode_data_packet({ReturnMode::kStrongest, kProductVlp16, 3'600'000'000u}, twelve, packet),
               std::invalid_argument);
  twelve[3].azimuth_cdeg = 36000;
  EXPECT_THROW(encode_data_packet({ReturnMode::kStrongest, kProductVlp16, 0}, twelve, packet), std::invalid_argument);
  std::array<std::uint8_t, kPositionPacketBytes> position{};
  EXPECT_THROW(encode_position_packet(0, PpsStatus::kLocked, std::string(129, 'x'), position), std::invalid_argument);
  EXPECT_THROW((void)format_rmc(Rmc{0, true, 91.0, 0.0}), std::invalid_argument);
}

TEST(Vlp16Encoder, RmcSentenceMatchesTheNmeaLayout) {
  // 2024-05-14 09:30:15.25 UTC, 40°42.85590' N, 111°47.83530' W.
  const Rmc fix{1'715'679'015'250'000'000, true, 40.0 + 42.8559 / 60.0, -(111.0 + 47.8353 / 60.0)};
  const std::string s = format_rmc(fix, 0.5, 271.25);
  EXPECT_EQ(s.substr(0, s.size() - 5), "$GPRMC,093015.25,A,4042.85590,N,11147.83530,W,000.5,271.2,140524,,,A");
  // The checksum, computed here by hand from the XOR of the characters between $ and *.
  unsigned x = 0;
  for (std::size_t i = 1; i + 5 < s.size(); ++i)
    x ^= static_cast<unsigned char>(s[i]);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", x);
  EXPECT_EQ(s.substr(s.size() - 5), tail);
}

TEST(Vlp16Encoder, PositionPacketsRoundTripThroughTheParser) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> lat(-89.9, 89.9), lon(-179.9, 179.9);
  std::uniform_int_distribution<std::int64_t> when(315'532'800'000'000'000, 3'471'292'799'000'000'000);  // 1980 … 2079
  for (int trial = 0; trial < 500; ++trial) {
    const Rmc fix{when(rng), trial % 3 != 0, lat(rng), lon(rng)};
    const auto toh = static_cast<std::uint32_t>(rng() % 3'600'000'000u);
    std::array<std::uint8_t, kPositionPacketBytes> bytes{};
    encode_position_packet(toh, PpsStatus::kLocked, format_rmc(fix), bytes);
    PositionPacket parsed;
    ASSERT_TRUE(parse_position_packet(bytes, parsed));
    ASSERT_EQ(parsed.nmea, NmeaError::kNone);
    EXPECT_EQ(parsed.toh_us, toh);
    EXPECT_EQ(parsed.pps, PpsStatus::kLocked);
    EXPECT_EQ(parsed.rmc.valid, fix.valid);
    EXPECT_NEAR(parsed.rmc.latitude_deg, fix.latitude_deg, 0.5e-5 / 60.0 + 1e-12);
    EXPECT_NEAR(parsed.rmc.longitude_deg, fix.longitude_deg, 0.5e-5 / 60.0 + 1e-12);
    EXPECT_LE(std::llabs(parsed.rmc.utc_ns - fix.utc_ns), 5'000'000);
  }
  // Minutes that round up to 60 carry into the degrees.
  const std::string s = format_rmc(Rmc{1'715'679'015'000'000'000, true, 10.0 - 1e-9, 20.0 - 1e-9});
  EXPECT_NE(s.find(",1000.00000,N,02000.00000,E,"), std::string::npos) << s;
}

}  // namespace
}  // namespace trajroi::vlp16
