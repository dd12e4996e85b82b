// Position packets and NMEA RMC sentences, built in the test; expected values worked out by
// hand from the sentences.
#include "trajroi/vlp16/position.hpp"

#include <gtest/gtest.h>

#include "packet_builder.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr std::int64_t kS = 1'000'000'000;
// 2016-01-21 00:00:00 UTC and 2012-12-11 00:00:00 UTC, seconds since 1970.
constexpr std::int64_t k20160121 = 1453334400;
constexpr std::int64_t k20121211 = 1355184000;

TEST(Vlp16Position, RmcFromTheMrptCapture) {
  Rmc rmc;
  ASSERT_EQ(parse_rmc("$GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.034,212.5,210116,0.0,E,A*2E\r\n", rmc),
            NmeaError::kNone);
  EXPECT_EQ(rmc.utc_ns, (k20160121 + 8 * 3600 + 18 * 60 + 2) * kS);
  EXPECT_TRUE(rmc.valid);
  EXPECT_DOUBLE_EQ(rmc.latitude_deg, 36.0 + 49.7478558 / 60.0);
  EXPECT_DOUBLE_EQ(rmc.longitude_deg, -(2.0 + 24.4542928 / 60.0));
}

TEST(Vlp16Position, OlderRmcWithoutFractionalSeconds) {
  Rmc rmc;
  ASSERT_EQ(parse_rmc("$GPRMC,214616,A,3708.3443,N,12139.4299,W,009.7,040.6,111212,013.8,E,D*0E", rmc),
            NmeaError::kNone);
  EXPECT_EQ(rmc.utc_ns, (k20121211 + 21 * 3600 + 46 * 60 + 16) * kS);
  EXPECT_DOUBLE_EQ(rmc.latitude_deg, 37.0 + 8.3443 / 60.0);
  EXPECT_DOUBLE_EQ(rmc.longitude_deg, -(121.0 + 39.4299 / 60.0));
}

// Sentences with a correct checksum computed here, so that only the named fault remains.
std::string with_checksum(const std::string& body) {
  unsigned sum = 0;
  for (const char c : body)
    sum ^= static_cast<unsigned char>(c);
  char text[4];
  std::snprintf(text, sizeof text, "%02X", sum);
  return "$" + body + "*" + text;
}

TEST(Vlp16Position, HemispheresTalkersAndVoidFixes) {
  Rmc rmc;
  ASSERT_EQ(parse_rmc(with_checksum("GNRMC,120000.50,V,3345.0000,S,15112.0000,E,0,0,010124,,,N"), rmc),
            NmeaError::kNone);
  EXPECT_FALSE(rmc.valid);
  EXPECT_DOUBLE_EQ(rmc.latitude_deg, -33.75);
  EXPECT_DOUBLE_EQ(rmc.longitude_deg, 151.2);
  EXPECT_EQ(rmc.utc_ns % kS, 500'000'000);
}

TEST(Vlp16Position, EveryNmeaFault) {
  Rmc rmc;
  EXPECT_EQ(parse_rmc("", rmc), NmeaError::kEmpty);
  EXPECT_EQ(parse_rmc("$GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.034,212.5,210116,0.0,E,A*2F", rmc),
            NmeaError::kBadChecksum);
  EXPECT_EQ(parse_rmc("$GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.034,212.5,210116,0.0,E,A", rmc),
            NmeaError::kBadChecksum);
  EXPECT_EQ(parse_rmc(with_checksum("GPGGA,081802.00,3649.7478558,N,00224.4542928,W,1,08,0.9,545.4,M,46.9,M,,"), rmc),
            NmeaError::kNotRmc);
  EXPECT_EQ(parse_rmc(with_checksum("GPRMC,081802.00,A,3649.74,N,00224.45,W,0,0,211316,,"), rmc),
            NmeaError::kMalformed);  // month 13
  EXPECT_EQ(parse_rmc(with_checksum("GPRMC,251802.00,A,3649.74,N,00224.45,W,0,0,210116,,"), rmc),
            NmeaError::kMalformed);  // hour 25
  EXPECT_EQ(parse_rmc(with_checksum("GPRMC,081802.00,A,3699.74,N,00224.45,W,0,0,210116,,"), rmc),
            NmeaError::kMalformed);  // 99 minutes
  EXPECT_EQ(parse_rmc(with_checksum("GPRMC,081802.00,A,3649.74,X,00224.45,W,0,0,210116,,"), rmc),
            NmeaError::kMalformed);
  EXPECT_EQ(parse_rmc(with_checksum("GPRMC,081802.00,A"), rmc), NmeaError::kMalformed);
  EXPECT_EQ(to_string(NmeaError::kBadChecksum), "bad_checksum");
}

TEST(Vlp16Position, PacketFieldsAndWrongSize) {
  const auto p = make_position_packet(
      1'082'341'969, 2, "$GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.034,212.5,210116,0.0,E,A*2E\r\n");
  PositionPacket packet;
  ASSERT_TRUE(parse_position_packet(p, packet));
  EXPECT_EQ(packet.toh_us, 1'082'341'969u);
  EXPECT_EQ(packet.pps, PpsStatus::kLocked);
  EXPECT_EQ(packet.nmea, NmeaError::kNone);
  EXPECT_FALSE(parse_position_packet(std::span(p).first(511), packet));
  // A sentence filling the whole 128-byte field, no NUL: read within the field only.
  auto full = make_position_packet(0, 0, std::string(200, 'A'));
  ASSERT_TRUE(parse_position_packet(full, packet));
  EXPECT_EQ(packet.nmea, NmeaError::kMalformed);
}

TEST(Vlp16Position, TopOfHourClockPlacesTimestampsInTheRightHour) {
  TopOfHourClock clock;
  PositionPacket packet;
  packet.pps = PpsStatus::kSynchronizing;
  packet.nmea = NmeaError::kNone;
  packet.rmc.valid = true;
  packet.rmc.utc_ns = (k20160121 + 8 * 3600 + 59 * 60 + 59) * kS;  // 08:59:59
  packet.toh_us = 3'599'000'400;
  EXPECT_FALSE(clock.on_position(packet));  // PPS not locked: the sensor's hour is not UTC's
  packet.pps = PpsStatus::kLocked;
  ASSERT_TRUE(clock.on_position(packet));
  const std::int64_t hour8 = (k20160121 + 8 * 3600) * kS;
  EXPECT_EQ(clock.to_utc_ns(3'599'500'000), hour8 + 3'599'500'000'000);
  EXPECT_EQ(clock.to_utc_ns(200'000), hour8 + 3600 * kS + 200'000'000);  // after the wrap: 09:00:00.2
  // The RMC already in the next hour while the sensor's timestamp is not yet.
  packet.rmc.utc_ns = (k20160121 + 9 * 3600) * kS;
  packet.toh_us = 3'599'999'900;
  ASSERT_TRUE(clock.on_position(packet));
  EXPECT_EQ(clock.to_utc_ns(3'599'999'950), hour8 + 3'599'999'950'000);
}

}  // namespace
}  // namespace trajroi::vlp16
