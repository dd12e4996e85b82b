// RTCM3 frames out of a real u-blox ZED-F9T stream (UBX, NMEA and RTCM3 interleaved), fed in
// pieces of every size: the (message number, length) sequence of gpsd's own decoding in its
// regression output (.chk), whole frames only; a corrupted frame is dropped alone, the next one
// still found; a frame cut by the end of the stream is never emitted.
#include "trajroi/framing/rtcm3.hpp"

#include <gtest/gtest.h>

#include <random>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "stream_feed.hpp"
#include "test_data.hpp"

namespace trajroi::framing {
namespace {

using Frames = std::vector<std::vector<std::uint8_t>>;

Frames frame_all(std::span<const std::uint8_t> all, unsigned seed, Rtcm3Framer& framer) {
  Frames out;
  std::mt19937 random(seed);
  for (std::size_t at = 0; at < all.size();) {
    const std::size_t n = std::min<std::size_t>(all.size() - at, 1 + random() % 700);
    framer.feed(all.subspan(at, n), [&out](std::span<const std::uint8_t> f) { out.emplace_back(f.begin(), f.end()); });
    at += n;
  }
  framer.finish([&out](std::span<const std::uint8_t> f) { out.emplace_back(f.begin(), f.end()); });
  return out;
}

// gpsd's decoding of the same log: each RTCM3 message's number and length, in order.
std::vector<std::pair<int, int>> gpsd_messages(const std::string& chk) {
  std::vector<std::pair<int, int>> out;
  const std::regex line(R"re(\{"class":"RTCM3","type":(\d+),"length":(\d+))re");
  for (std::sregex_iterator it(chk.begin(), chk.end(), line), end; it != end; ++it) {
    const std::pair<int, int> m{std::stoi((*it)[1]), std::stoi((*it)[2])};
    // gpsd prints some messages twice in a row (22 of the 26 type-1230 messages: the log
    // holds each once; no epoch of this receiver repeats a message): taken once.
    if (out.empty() || out.back() != m) out.push_back(m);
  }
  return out;
}

TEST(Rtcm3Framer, FramesWhatGpsdDecodesInARealF9tStream) {
  TRAJROI_REQUIRE_DATA(path, "ublox/gpsd/ublox-zed-f9t-rtcm3.log");
  const std::string bytes = test::read_file(path);
  const auto expected = gpsd_messages(test::read_file(path.string() + ".chk"));
  ASSERT_EQ(expected.size(), 182U);
  for (const unsigned seed : {1U, 2U, 3U}) {
    Rtcm3Framer framer;
    const Frames frames = frame_all(test::as_bytes(bytes), seed, framer);
    ASSERT_EQ(frames.size(), expected.size()) << "seed " << seed;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      EXPECT_EQ(rtcm3_message_number(frames[i]), expected[i].first) << "frame " << i;
      EXPECT_EQ(frames[i].size() - kRtcm3Overhead, static_cast<std::size_t>(expected[i].second)) << "frame " << i;
    }
    // 0xD3 bytes inside the UBX frames that look like a header: candidates whose CRC fails.
    EXPECT_LE(framer.counters().checksum_errors, 5U);
  }
}

TEST(Rtcm3Framer, ACorruptedFrameIsDroppedAloneAndACutOneNeverEmitted) {
  TRAJROI_REQUIRE_DATA(path, "ublox/gpsd/ublox-zed-f9t-rtcm3.log");
  const std::string bytes = test::read_file(path);
  Rtcm3Framer clean_framer;
  const Frames clean = frame_all(test::as_bytes(bytes), 7, clean_framer);
  // The stream as the frames alone, the 10th frame's message corrupted (one bit), and its
  // length field made to claim far more (1023 bytes): the frames behind must survive.
  std::vector<std::uint8_t> stream;
  for (std::size_t i = 0; i < clean.size(); ++i) {
    std::vector<std::uint8_t> f = clean[i];
    if (i == 10) f[20] ^= 0x01;
    if (i == 20) f[1] = 0x03, f[2] = 0xFF;
    stream.insert(stream.end(), f.begin(), f.end());
  }
  const std::vector<std::uint8_t> last = clean.back();
  stream.insert(stream.end(), last.begin(), last.end() - 1);  // cut: one byte short
  Rtcm3Framer framer;
  const Frames frames = frame_all(stream, 9, framer);
  ASSERT_EQ(frames.size(), clean.size() - 2);
  std::size_t k = 0;
  for (std::size_t i = 0; i < clean.size(); ++i) {
    if (i == 10 || i == 20) continue;
    EXPECT_EQ(frames[k++], clean[i]) << "frame " << i;
  }
  EXPECT_EQ(framer.counters().checksum_errors, 2U);  // the flipped bit, the false length
  EXPECT_EQ(framer.counters().truncated, 1U);
}

TEST(Rtcm3Framer, TheMessageNumberIsTheFirst12Bits) {
  const std::uint8_t frame[] = {0xD3, 0x00, 0x02, 0x3E, 0xD0, 0, 0, 0};  // 1005 = 0x3ED
  EXPECT_EQ(rtcm3_message_number(frame), 1005);
}

}  // namespace
}  // namespace trajroi::framing
