// The NTRIP client's protocol against RTCM 10410.1's (NTRIP 2.0) and NTRIP 1.0's forms, the
// chunked transfer of RFC 9112 §7.1 (its body split at every byte), and the GGA sentence
// against NMEA 0183's classic example and its own checksum rule.
#include "trajroi/corrections/ntrip.hpp"

#include <gtest/gtest.h>

#include <string>

#include "trajroi/corrections/gga.hpp"
#include "trajroi/framing/protocol_sniffer.hpp"

namespace trajroi::corrections {
namespace {

TEST(NtripUrl, PartsAndDefaults) {
  const NtripUrl u = parse_ntrip_url("ntrip://rover:s3cret@caster.example:2102/RTCM3_MSM7?version=1");
  EXPECT_EQ(u.user, "rover");
  EXPECT_EQ(u.password, "s3cret");
  EXPECT_EQ(u.host, "caster.example");
  EXPECT_EQ(u.port, 2102);
  EXPECT_EQ(u.mountpoint, "RTCM3_MSM7");
  EXPECT_EQ(u.version, 1);
  EXPECT_EQ(u.redacted(), "ntrip://rover:***@caster.example:2102/RTCM3_MSM7");
  const NtripUrl d = parse_ntrip_url("ntrip://127.0.0.1/MOUNT");
  EXPECT_EQ(d.port, 2101);
  EXPECT_EQ(d.version, 2);
  EXPECT_TRUE(d.user.empty());
}

TEST(NtripUrl, MistakesAreNamed) {
  const auto why = [](const char* url) {
    try {
      (void)parse_ntrip_url(url);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(why("http://host/M"), "http://host/M: not an ntrip:// URL (ntrip://user:password@host:port/mountpoint)");
  EXPECT_EQ(why("ntrip://host:2101"), "ntrip://host:2101: no mountpoint (ntrip://host:port/MOUNTPOINT)");
  EXPECT_EQ(why("ntrip://host:99999/M"), "ntrip://host:99999/M: port '99999'");
  EXPECT_EQ(why("ntrip://user@/M"), "ntrip://user@/M: no host");
  EXPECT_EQ(why("ntrip://h/M?v=3"), "ntrip://h/M?v=3: unknown option 'v=3' (version=1 or version=2)");
}

TEST(NtripRequest, Version2IsHttp11WithBasicCredentialsAndTheGgaHeader) {
  const NtripUrl u = parse_ntrip_url("ntrip://rover:s3cret@caster.example:2101/VRS");
  EXPECT_EQ(ntrip_request(u, "trajroi/0.1", "$GPGGA,1*00\r\n"),
            "GET /VRS HTTP/1.1\r\nHost: caster.example:2101\r\nNtrip-Version: Ntrip/2.0\r\n"
            "User-Agent: NTRIP trajroi/0.1\r\nAuthorization: Basic cm92ZXI6czNjcmV0\r\n"
            "Ntrip-GGA: $GPGGA,1*00\r\nConnection: close\r\n\r\n");
}

TEST(NtripRequest, Version1IsHttp10WithTheGgaAfterTheHead) {
  const NtripUrl u = parse_ntrip_url("ntrip://caster.example/VRS?version=1");
  EXPECT_EQ(ntrip_request(u, "trajroi/0.1", "$GPGGA,1*00\r\n"),
            "GET /VRS HTTP/1.0\r\nUser-Agent: NTRIP trajroi/0.1\r\n\r\n$GPGGA,1*00\r\n");
}

TEST(NtripAnswer, TheCastersAnswers) {
  const NtripAnswer icy = parse_ntrip_answer("ICY 200 OK\r\n\xD3\x00");
  EXPECT_EQ(icy.kind, NtripAnswer::Kind::kStream);
  EXPECT_EQ(icy.head_bytes, 12U);
  const NtripAnswer v2 = parse_ntrip_answer(
      "HTTP/1.1 200 OK\r\nNtrip-Version: Ntrip/2.0\r\nContent-Type: gnss/data\r\nTransfer-Encoding: chunked\r\n\r\n1A");
  EXPECT_EQ(v2.kind, NtripAnswer::Kind::kStream);
  EXPECT_TRUE(v2.chunked);
  const NtripAnswer table = parse_ntrip_answer("SOURCETABLE 200 OK\r\nContent-Type: text/plain\r\n\r\nSTR;A;");
  EXPECT_EQ(table.kind, NtripAnswer::Kind::kSourceTable);
  const NtripAnswer table2 =
      parse_ntrip_answer("HTTP/1.1 200 OK\r\nContent-Type: gnss/sourcetable\r\nContent-Length: 9\r\n\r\n");
  EXPECT_EQ(table2.kind, NtripAnswer::Kind::kSourceTable);
  const NtripAnswer refused = parse_ntrip_answer("HTTP/1.1 401 Unauthorized\r\nWWW-Authenticate: Basic\r\n\r\n");
  EXPECT_EQ(refused.kind, NtripAnswer::Kind::kRefused);
  EXPECT_EQ(refused.status, 401);
  EXPECT_EQ(refused.status_line, "HTTP/1.1 401 Unauthorized");
  // RTKLIB's caster: the status line alone, then it closes.
  EXPECT_EQ(parse_ntrip_answer("HTTP/1.0 401 Unauthorized\r\n").kind, NtripAnswer::Kind::kIncomplete);
  const NtripAnswer closed = parse_ntrip_answer("HTTP/1.0 401 Unauthorized\r\n", true);
  EXPECT_EQ(closed.kind, NtripAnswer::Kind::kRefused);
  EXPECT_EQ(closed.status, 401);
  EXPECT_EQ(parse_ntrip_answer("ICY 2").kind, NtripAnswer::Kind::kIncomplete);
  EXPECT_EQ(parse_ntrip_answer("HTTP/1.1 200 OK\r\nContent-Type: gnss/data\r\n").kind, NtripAnswer::Kind::kIncomplete);
  // RTCM bytes where the answer should be (a caster that skips its answer, or another service).
  EXPECT_EQ(parse_ntrip_answer(std::string_view("\xD3\x00\x13>\xD0\x00\x03\x8A\r\n", 10)).kind,
            NtripAnswer::Kind::kGarbage);
  EXPECT_EQ(parse_ntrip_answer("SSH-2.0-OpenSSH_9.2\r\n").kind, NtripAnswer::Kind::kGarbage);
  // A status that is not three digits is no status (the fuzzer's first find: 28 digits overflowed an int).
  const NtripAnswer huge = parse_ntrip_answer("HTTP/1.1 2555555555555555555555555500 OK\r\n\r\n");
  EXPECT_EQ(huge.kind, NtripAnswer::Kind::kRefused);
  EXPECT_EQ(huge.status, 0);
  EXPECT_EQ(parse_ntrip_answer("HTTP/1.1 2e2 OK\r\n\r\n").status, 0);
  EXPECT_EQ(parse_ntrip_answer("HTTP/1.1 200.0 OK\r\n\r\n").kind, NtripAnswer::Kind::kRefused);
}

TEST(SourceTable, StreamRecords) {
  const std::string body =
      "CAS;caster.example;2101;Example;BKG;0;DEU;50.09;8.66;0.0.0.0;0;http://example\r\n"
      "STR;FFMJ00DEU0;Frankfurt;RTCM 3.3;1005(10),1077(1),1087(1);2;GPS+GLO;EUREF;DEU;50.09;8.66;0;0;"
      "Trimble;none;B;N;4400;\r\n"
      "STR;VRS_MSM;Network VRS;RTCM 3.2;1004(1);2;GPS;NET;DEU;51.00;10.00;1;1;sNTRIP;none;B;N;9600;\r\n"
      "STR;F9T;RTKLIB's caster sends three fields\r\n"
      "STR;\r\n"
      "ENDSOURCETABLE\r\n";
  const auto streams = parse_source_table(body);
  ASSERT_EQ(streams.size(), 3U);
  EXPECT_EQ(streams[2].mountpoint, "F9T");
  EXPECT_EQ(streams[2].format, "");
  EXPECT_EQ(streams[0].mountpoint, "FFMJ00DEU0");
  EXPECT_EQ(streams[0].format, "RTCM 3.3");
  EXPECT_EQ(streams[0].nav_system, "GPS+GLO");
  EXPECT_DOUBLE_EQ(streams[0].latitude_deg, 50.09);
  EXPECT_FALSE(streams[0].wants_gga);
  EXPECT_EQ(streams[1].mountpoint, "VRS_MSM");
  EXPECT_TRUE(streams[1].wants_gga);
}

TEST(ChunkedDecoder, RfcFormSplitAtEveryByte) {
  const std::string body = "4\r\nWiki\r\n5;name=value\r\npedia\r\nE\r\n in\r\n\r\nchunks.\r\n0\r\n\r\n";
  for (std::size_t cut = 0; cut <= body.size(); ++cut) {
    ChunkedDecoder d;
    std::vector<std::uint8_t> out;
    const auto bytes = std::span(reinterpret_cast<const std::uint8_t*>(body.data()), body.size());
    ChunkedDecoder::Status s = d.feed(bytes.first(cut), out);
    if (s != ChunkedDecoder::Status::kEnd) s = d.feed(bytes.subspan(cut), out);
    EXPECT_EQ(s, ChunkedDecoder::Status::kEnd) << cut;
    EXPECT_EQ(std::string(out.begin(), out.end()), "Wikipedia in\r\n\r\nchunks.") << cut;
  }
  ChunkedDecoder bad;
  std::vector<std::uint8_t> out;
  const std::string garbage = "zz\r\n";
  EXPECT_EQ(bad.feed(std::span(reinterpret_cast<const std::uint8_t*>(garbage.data()), garbage.size()), out),
            ChunkedDecoder::Status::kError);
  EXPECT_EQ(bad.error(), "bad chunk size");
}

TEST(Gga, NmeasClassicExampleAndItsChecksum) {
  // NMEA 0183's example: 12:35:19 UTC, 48°07.038' N, 11°31.000' E, GPS fix, 8 satellites,
  // HDOP 0.9, 545.4 m above mean sea level, geoid 46.9 m.
  GgaFix f;
  f.utc_ns = (12 * 3600 + 35 * 60 + 19) * 1'000'000'000LL +
             1'700'000'000'000'000'000LL / 86'400'000'000'000LL * 86'400'000'000'000LL;
  f.latitude_deg = 48.0 + 7.038 / 60.0;
  f.longitude_deg = 11.0 + 31.0 / 60.0;
  f.height_msl_m = 545.4;
  f.geoid_separation_m = 46.9;
  f.quality = 1;
  f.satellites = 8;
  f.hdop = 0.9;
  const std::string s = gga_sentence(f);
  EXPECT_EQ(s.substr(0, s.find('*')), "$GPGGA,123519.00,4807.0380000,N,01131.0000000,E,1,08,0.9,545.400,M,46.900,M,,");
  // Its checksum: the sniffer counts only checksum-correct NMEA sentences.
  framing::ProtocolSniffer sniffer;
  sniffer.feed(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
  EXPECT_EQ(sniffer.counters().nmea_sentences, 1U);
  f.latitude_deg = -33.8568;
  f.longitude_deg = -151.2153;
  const std::string south = gga_sentence(f);
  EXPECT_NE(south.find(",3351.4080000,S,15112.9180000,W,"), std::string::npos) << south;
}

}  // namespace
}  // namespace trajroi::corrections
