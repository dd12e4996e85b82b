// gnss.corrections.url: every source's form, its defaults, the text logs show (never a
// password), and each mistake named. Rtcm3Intake against the frames of a real u-blox RTCM3
// stream (the rtcm3 framing test checks them against gpsd's decoding): split at every byte,
// with noise, and across a lost connection.
#include "trajroi/corrections/corrections_url.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "stream_peers.hpp"
#include "test_data.hpp"
#include "trajroi/corrections/rtcm3_intake.hpp"

namespace trajroi::corrections {
namespace {

using Kind = CorrectionsUrl::Kind;

std::string why(const char* url) {
  try {
    (void)parse_corrections_url(url);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(CorrectionsUrl, EverySource) {
  const CorrectionsUrl n = parse_corrections_url("ntrip://rover:s3cret@caster.example:2102/MSM7?version=1");
  EXPECT_EQ(n.kind, Kind::kNtrip);
  EXPECT_EQ(n.ntrip.mountpoint, "MSM7");
  EXPECT_EQ(n.ntrip.version, 1);
  EXPECT_EQ(n.redacted(), "ntrip://rover:***@caster.example:2102/MSM7");

  const CorrectionsUrl t = parse_corrections_url("tcp://192.168.1.20:9001");
  EXPECT_EQ(t.kind, Kind::kTcp);
  EXPECT_EQ(t.ntrip.host, "192.168.1.20");
  EXPECT_EQ(t.ntrip.port, 9001);
  EXPECT_EQ(t.redacted(), "tcp://192.168.1.20:9001");

  const CorrectionsUrl u = parse_corrections_url("udp://:9000");
  EXPECT_EQ(u.kind, Kind::kUdp);
  EXPECT_EQ(u.bind_address, "0.0.0.0");
  EXPECT_EQ(u.port, 9000);
  EXPECT_EQ(u.redacted(), "udp://0.0.0.0:9000");
  EXPECT_EQ(parse_corrections_url("udp://127.0.0.1:9000").bind_address, "127.0.0.1");

  const CorrectionsUrl s = parse_corrections_url("serial:///dev/ttyUSB1?baud=115200");
  EXPECT_EQ(s.kind, Kind::kSerial);
  EXPECT_EQ(s.device, "/dev/ttyUSB1");
  EXPECT_EQ(s.baud, 115200);
  EXPECT_EQ(parse_corrections_url("serial:///dev/ttyUSB1").baud, 57600);
  EXPECT_EQ(s.redacted(), "serial:///dev/ttyUSB1?baud=115200");

  const CorrectionsUrl l = parse_corrections_url("lcm://BASE_RTCM");
  EXPECT_EQ(l.kind, Kind::kLcm);
  EXPECT_EQ(l.channel, "BASE_RTCM");
  EXPECT_EQ(l.redacted(), "lcm://BASE_RTCM");
}

TEST(CorrectionsUrl, MistakesAreNamed) {
  EXPECT_EQ(why("caster.example:2101"),
            "caster.example:2101: not a URL (ntrip://, tcp://, udp://, serial:// or lcm://)");
  EXPECT_EQ(why("http://caster.example/M"),
            "http://caster.example/M: unknown scheme 'http' (ntrip, tcp, udp, serial or lcm)");
  EXPECT_EQ(why("tcp://caster.example"), "tcp://caster.example: no port (tcp://host:PORT)");
  EXPECT_EQ(why("tcp://:9001"), "tcp://:9001: no host");
  EXPECT_EQ(why("tcp://host:0"), "tcp://host:0: port '0' (1 … 65535)");
  EXPECT_EQ(why("udp://:65536"), "udp://:65536: port '65536' (1 … 65535)");
  EXPECT_EQ(why("udp://:90x0"), "udp://:90x0: port '90x0' (1 … 65535)");
  EXPECT_EQ(why("serial://ttyUSB1"), "serial://ttyUSB1: no device path (serial:///dev/ttyUSB1)");
  EXPECT_EQ(why("serial:///dev/ttyUSB1?baud=fast"), "serial:///dev/ttyUSB1?baud=fast: baud rate 'fast'");
  EXPECT_EQ(why("serial:///dev/ttyUSB1?parity=even"),
            "serial:///dev/ttyUSB1?parity=even: unknown option 'parity=even' (baud=N)");
  EXPECT_EQ(why("lcm://"), "lcm://: channel '' (lcm://CHANNEL)");
  EXPECT_EQ(why("lcm://A/B"), "lcm://A/B: channel 'A/B' (lcm://CHANNEL)");
  EXPECT_NE(why("ntrip://host:2101"), "accepted");  // no mountpoint: parse_ntrip_url names it
}

using corrections_test::Bytes;

TEST(Rtcm3Intake, RealFramesSplitAtEveryByteWithNoiseAndALostConnection) {
  TRAJROI_REQUIRE_DATA(path, "ublox/gpsd/ublox-zed-f9t-rtcm3.log");
  const std::vector<Bytes> frames = corrections_test::log_frames(trajroi::test::read_file(path));
  ASSERT_EQ(frames.size(), 182U);
  std::size_t corrupted = 0;
  const Bytes first = corrections_test::with_noise(frames, 0, 100, corrupted);
  const Bytes second = corrections_test::with_noise(frames, 100, 182, corrupted);

  Rtcm3Intake intake;
  std::vector<Bytes> out;
  const auto sink = [&out](std::span<const std::uint8_t> f) { out.emplace_back(f.begin(), f.end()); };
  for (const std::uint8_t b : first)
    intake.feed(std::span(&b, 1), sink);
  // The connection drops in the middle of frame 100: its start must not join the next stream.
  const Bytes& cut = frames[100];
  const std::uint64_t other_before = intake.counters().other_bytes;
  intake.feed(std::span(cut.data(), cut.size() / 2), sink);
  EXPECT_EQ(intake.counters().other_bytes, other_before);  // still a frame in progress
  intake.restart();
  EXPECT_EQ(intake.counters().other_bytes, other_before + cut.size() / 2);  // given up, counted
  for (const std::uint8_t b : second)
    intake.feed(std::span(&b, 1), sink);

  EXPECT_EQ(out, frames);
  const CorrectionCounters& c = intake.counters();
  EXPECT_EQ(c.frames, frames.size());
  EXPECT_EQ(c.crc_errors, corrupted);
  EXPECT_EQ(c.bytes, first.size() + cut.size() / 2 + second.size());
  std::size_t frame_bytes = 0;
  std::map<std::uint16_t, std::uint64_t> by_message;
  for (const Bytes& f : frames) {
    frame_bytes += f.size();
    ++by_message[framing::rtcm3_message_number(f)];
  }
  EXPECT_EQ(c.by_message, by_message);
  // Everything else is noise, corrupted copies or the cut frame's half: none of it a frame.
  EXPECT_EQ(c.other_bytes, c.bytes - frame_bytes);
}

}  // namespace
}  // namespace trajroi::corrections
