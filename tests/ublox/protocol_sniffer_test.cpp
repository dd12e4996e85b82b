// What a serial port carries besides its binary protocol, recognised on real logs: the NMEA
// sentences and RTCM3 frames the data README counts in gpsd's u-blox logs (its own scanner
// checked every XOR checksum and CRC-24Q), fed in pieces of every size; random bytes (a wrong
// baud rate) recognised as none; VectorNav ASCII sentences by both of their checksums.
#include "trajroi/framing/protocol_sniffer.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

#include "stream_feed.hpp"
#include "test_data.hpp"

namespace trajroi::framing {
namespace {

SnifferCounters sniff(const std::string& bytes, unsigned seed) {
  ProtocolSniffer sniffer;
  std::mt19937 random(seed);
  const auto all = test::as_bytes(bytes);
  for (std::size_t at = 0; at < all.size();) {
    const std::size_t n = std::min<std::size_t>(all.size() - at, 1 + random() % 300);
    sniffer.feed(all.subspan(at, n));
    at += n;
  }
  return sniffer.counters();
}

struct Expected {
  const char* log;
  std::uint64_t nmea, rtcm3;
};

class SnifferOnGpsdLogs : public testing::TestWithParam<Expected> {};

TEST_P(SnifferOnGpsdLogs, CountsWhatTheDataReadmeCounts) {
  TRAJROI_REQUIRE_DATA(path, std::string("ublox/gpsd/") + GetParam().log);
  const std::string bytes = test::read_file(path);
  for (const unsigned seed : {1U, 2U, 3U}) {
    const SnifferCounters c = sniff(bytes, seed);
    EXPECT_EQ(c.nmea_sentences, GetParam().nmea) << GetParam().log;
    EXPECT_EQ(c.rtcm3_frames, GetParam().rtcm3) << GetParam().log;
    EXPECT_EQ(c.vn100_ascii_sentences, 0U) << GetParam().log;
  }
}

// ../shared/data/README.md, section 2: "871 NMEA sentences; 224 RTCM3 frames", "182 RTCM3
// frames" (the last, truncated one not counted), "14 $GNTXT", "52 NMEA sentences", none.
INSTANTIATE_TEST_SUITE_P(Readme, SnifferOnGpsdLogs,
                         testing::Values(Expected{"ublox-zed-f9r.log", 871, 224},
                                         Expected{"ublox-zed-f9t-rtcm3.log", 0, 182},
                                         Expected{"ublox-neo-m8l.log", 14, 0},
                                         Expected{"ublox8-uniqid-monhw.log", 52, 0},
                                         Expected{"ublox-zed-f9p-hp.log", 0, 0}),
                         [](const testing::TestParamInfo<Expected>& p) { return test::file_test_name(p.param.log); });

TEST(ProtocolSniffer, RandomBytesAreNoneOfThem) {
  std::mt19937 random(7);
  std::string noise(1 << 20, '\0');
  for (char& c : noise)
    c = static_cast<char>(random());
  const SnifferCounters c = sniff(noise, 1);
  EXPECT_EQ(c.nmea_sentences + c.vn100_ascii_sentences + c.rtcm3_frames, 0U);
}

// A VectorNav ASCII sentence with its 8-bit XOR checksum, or its 16-bit CRC (CRC-16-CCITT,
// VectorNav's "*XXXX" form), computed here the plain way.
std::string vn_sentence(const std::string& body, bool crc16) {
  char tail[8];
  if (crc16) {
    std::uint16_t crc = 0;
    for (const char ch : body) {  // the textbook bit-serial CRC-16/XMODEM (poly 0x1021, init 0)
      crc ^= static_cast<std::uint16_t>(static_cast<std::uint8_t>(ch) << 8);
      for (int i = 0; i < 8; ++i)
        crc = static_cast<std::uint16_t>((crc & 0x8000) != 0 ? (crc << 1) ^ 0x1021 : crc << 1);
    }
    std::snprintf(tail, sizeof tail, "*%04X", crc);
  } else {
    unsigned x = 0;
    for (const char ch : body)
      x ^= static_cast<std::uint8_t>(ch);
    std::snprintf(tail, sizeof tail, "*%02X", x);
  }
  return "$" + body + tail + "\r\n";
}

TEST(ProtocolSniffer, VectorNavAsciiByEitherChecksumAndNotWhenCorrupted) {
  const std::string ymr =
      "VNYMR,+006.380,+000.023,-001.953,+1.0640,-0.2531,+3.0614,+00.005,+00.344,-09.758,-0.001222,-0.000450,-0.001218";
  std::string text;
  for (int i = 0; i < 10; ++i)
    text += vn_sentence(ymr, i % 2 == 1);
  std::string corrupted = vn_sentence(ymr, false);
  corrupted[10] = '7';
  text += corrupted;
  text += vn_sentence("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,", false);
  const SnifferCounters c = sniff(text, 3);
  EXPECT_EQ(c.vn100_ascii_sentences, 10U);
  EXPECT_EQ(c.nmea_sentences, 1U);
  EXPECT_EQ(c.rtcm3_frames, 0U);
}

}  // namespace
}  // namespace trajroi::framing
