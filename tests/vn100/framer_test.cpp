// The VN-100 framer, decoder and commands on frames built here.
#include "trajroi/vn100/framer.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "stream_feed.hpp"
#include "trajroi/framing/little_endian.hpp"
#include "trajroi/vn100/command.hpp"
#include "trajroi/vn100/decoder.hpp"

namespace trajroi::vn100 {
namespace {

using Bytes = std::vector<std::uint8_t>;

void append(Bytes& out, const Bytes& more) {
  for (const std::uint8_t b : more)
    out.push_back(b);
}
void put_f32(Bytes& out, float v) {
  framing::put_le_u32(out, std::bit_cast<std::uint32_t>(v));
}

// The little-endian readers every framer uses, at every offset (unaligned included), against
// values written out byte by byte here.
TEST(LittleEndian, ReadsFieldsAtAnyOffset) {
  const Bytes bytes{0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0xFE, 0xFF, 0x00, 0x00, 0x80, 0x3F};
  for (std::size_t at = 0; at + 2 <= bytes.size(); ++at) {
    EXPECT_EQ(framing::le_u16(bytes, at), bytes[at] + 256U * bytes[at + 1]) << at;
  }
  for (std::size_t at = 0; at + 4 <= bytes.size(); ++at) {
    std::uint32_t expected = 0;
    for (std::size_t k = 4; k-- > 0;)
      expected = expected * 256U + bytes[at + k];
    EXPECT_EQ(framing::le_u32(bytes, at), expected) << at;
  }
  EXPECT_EQ(framing::le_u64(bytes, 1), 0x0908070605040302ULL);
  EXPECT_EQ(framing::le_i16(bytes, 9), -2);       // FE FF
  EXPECT_EQ(framing::le_f32(bytes, 11), 1.0F);    // 00 00 80 3F
  EXPECT_EQ(framing::le_i32(bytes, 7), -128760);  // 08 09 FE FF
}

// Common group: TimeStartup, TimeGps, YawPitchRoll, Quaternion, AngularRate, Accel, MagPres.
Bytes common_frame(std::uint64_t startup_ns, float yaw_deg) {
  Bytes payload;
  framing::put_le_u64(payload, startup_ns);
  framing::put_le_u64(payload, 1'300'000'000'123'456'789ULL);
  for (const float v : {yaw_deg, -2.5F, 1.25F})
    put_f32(payload, v);
  for (const float v : {0.0F, 0.0F, 0.38268343F, 0.92387953F})
    put_f32(payload, v);
  for (const float v : {0.01F, -0.02F, 0.03F})
    put_f32(payload, v);
  for (const float v : {0.1F, 0.2F, -9.81F})
    put_f32(payload, v);
  for (const float v : {0.2F, 0.0F, 0.4F, 21.5F, 101.3F})
    put_f32(payload, v);
  std::array<std::uint16_t, 8> fields{};
  fields[0] = 0x0001 | 0x0002 | 0x0008 | 0x0010 | 0x0020 | 0x0100 | 0x0400;
  return encode_frame(fields, payload);
}

struct Result {
  std::vector<Sample> samples;
  framing::FramerCounters counters;
};

Result run(std::span<const std::uint8_t> bytes, std::size_t chunk = 0) {
  Framer framer;
  Result r;
  const auto sink = [&](std::span<const std::uint8_t> frame) {
    Sample s;
    EXPECT_TRUE(decode(frame, s));
    r.samples.push_back(s);
  };
  test::feed_in_chunks(framer, bytes, chunk, sink);
  r.counters = framer.counters();
  return r;
}

TEST(Vn100Crc, CcittOfTheCheckString) {
  // CRC-16/XMODEM (poly 0x1021, init 0) of "123456789" is 0x31C3.
  const std::string check = "123456789";
  EXPECT_EQ(crc16_ccitt({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0x31C3);
}

TEST(Vn100Decoder, CommonGroupFieldsAndTimes) {
  const Bytes frame = common_frame(5'000'000'000ULL, 123.5F);
  ASSERT_EQ(frame.size(), 1U + 1U + 2U + 8U + 8U + 12U + 16U + 12U + 12U + 20U + 2U);
  Sample s;
  ASSERT_TRUE(decode(frame, s));
  EXPECT_TRUE(s.has(Field::kTimeStartup));
  EXPECT_TRUE(s.has(Field::kTimeGps));
  EXPECT_TRUE(s.has(Field::kPressure));
  EXPECT_FALSE(s.has(Field::kDcm));
  EXPECT_EQ(s.time_startup_ns, 5'000'000'000ULL);
  EXPECT_EQ(s.time_gps_ns, 1'300'000'000'123'456'789ULL);
  EXPECT_EQ(s.ypr_deg[0], 123.5F);
  EXPECT_EQ(s.quaternion_xyzw[3], 0.92387953F);
  EXPECT_EQ(s.angular_rate_rps[2], 0.03F);
  EXPECT_EQ(s.accel_mps2[2], -9.81F);
  EXPECT_EQ(s.mag_gauss[2], 0.4F);
  EXPECT_EQ(s.temperature_c, 21.5F);
  EXPECT_EQ(s.pressure_kpa, 101.3F);
}

TEST(Vn100Decoder, TimeGroupAndAttitudeGroupTogether) {
  Bytes payload;
  framing::put_le_u64(payload, 77);  // Time: TimeStartup
  for (const float v : {10.0F, 20.0F, 30.0F})
    put_f32(payload, v);  // Attitude: YawPitchRoll
  for (const float v : {1.0F, 2.0F, 3.0F})
    put_f32(payload, v);  // Attitude: LinearAccelBody
  std::array<std::uint16_t, 8> fields{};
  fields[1] = 0x0001;
  fields[4] = 0x0002 | 0x0040;
  const Bytes frame = encode_frame(fields, payload);
  EXPECT_EQ(frame[1], 0x12);
  Sample s;
  ASSERT_TRUE(decode(frame, s));
  EXPECT_EQ(s.time_startup_ns, 77U);
  EXPECT_EQ(s.ypr_deg[2], 30.0F);
  EXPECT_EQ(s.linear_accel_body_mps2[1], 2.0F);
}

TEST(Vn100Framer, CorruptCrcDropsOnlyThatFrame) {
  Bytes stream = common_frame(1, 1.0F);
  Bytes bad = common_frame(2, 2.0F);
  bad[20] ^= 0x01;
  append(stream, bad);
  append(stream, common_frame(3, 3.0F));
  const Result r = run(stream);
  ASSERT_EQ(r.samples.size(), 2U);
  EXPECT_EQ(r.samples[0].time_startup_ns, 1U);
  EXPECT_EQ(r.samples[1].time_startup_ns, 3U);
  EXPECT_EQ(r.counters.checksum_errors, 1U);
}

// A header whose group byte was corrupted into a larger selection (a "corrupt length") must
// not swallow the frames that follow.
TEST(Vn100Framer, CorruptGroupSelectionDoesNotSwallowFollowingFrames) {
  Bytes corrupt = common_frame(1, 1.0F);
  corrupt[2] = 0xFF;  // Common mask low byte: every field, about 200 bytes claimed
  corrupt[3] = 0x7F;
  Bytes stream = corrupt;
  for (std::uint64_t i = 0; i < 4; ++i)
    append(stream, common_frame(10 + i, 0.0F));
  for (const std::size_t chunk : {std::size_t{0}, std::size_t{1}, std::size_t{17}}) {
    const Result r = run(stream, chunk);
    ASSERT_EQ(r.samples.size(), 4U) << "chunk " << chunk;
    EXPECT_EQ(r.samples.front().time_startup_ns, 10U);
  }
}

TEST(Vn100Framer, UnsizableSelectionsAreSkippedAndCounted) {
  Bytes stream{kSync, 0x08, 0x01, 0x00};  // GPS group: not a VN-100 output
  append(stream, common_frame(1, 0.0F));
  stream.insert(stream.end(), {kSync, 0x01, 0x00, 0x80});  // Common mask with the extension bit
  append(stream, common_frame(2, 0.0F));
  const Result r = run(stream);
  EXPECT_EQ(r.samples.size(), 2U);
  EXPECT_EQ(r.counters.unsizable, 2U);
  EXPECT_EQ(r.counters.skipped_bytes, 8U);
}

TEST(Vn100Framer, GarbageAndMarkersBetweenFrames) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> byte(0, 255);
  Bytes stream;
  for (std::uint64_t i = 0; i < 300; ++i) {
    const std::string marker = "M," + std::to_string(i * 100) + "\r\nB,\n\r\n";
    stream.insert(stream.end(), marker.begin(), marker.end());
    const int n = byte(rng) % 20;
    for (int k = 0; k < n; ++k)
      stream.push_back(static_cast<std::uint8_t>(byte(rng)));
    append(stream, common_frame(i, 0.0F));
  }
  const Result r = run(stream);
  std::size_t ours = 0;
  for (const Sample& s : r.samples)
    ours += s.has(Field::kTimeStartup) ? 1U : 0U;
  EXPECT_EQ(ours, 300U);
  EXPECT_EQ(run(stream, 1).samples.size(), r.samples.size());
}

TEST(Vn100Framer, StreamCutAtEveryOffset) {
  Bytes stream{'B', ',', '\n'};
  std::vector<std::size_t> ends;
  for (std::uint64_t i = 0; i < 3; ++i) {
    append(stream, common_frame(i, 0.0F));
    ends.push_back(stream.size());
  }
  for (std::size_t cut = 0; cut <= stream.size(); ++cut) {
    const Result r = run(std::span<const std::uint8_t>(stream).first(cut), 5);
    std::size_t complete = 0;
    for (const std::size_t end : ends)
      complete += end <= cut ? 1U : 0U;
    EXPECT_EQ(r.samples.size(), complete) << "cut " << cut;
    EXPECT_EQ(r.counters.frame_bytes + r.counters.skipped_bytes, cut) << "cut " << cut;
  }
}

TEST(Vn100Encode, RejectsPayloadsThatDoNotMatchTheLayout) {
  std::array<std::uint16_t, 8> fields{};
  fields[0] = 0x0008;  // YawPitchRoll: 12 bytes
  EXPECT_THROW((void)encode_frame(fields, Bytes(11)), std::invalid_argument);
  fields[3] = 0x0001;  // GPS group
  EXPECT_THROW((void)encode_frame(fields, Bytes(20)), std::invalid_argument);
}

TEST(Vn100Command, ChecksumsOfPublishedCommands) {
  // Examples seen in public VN-100 / VN-300 client code.
  EXPECT_EQ(ascii_command("VNRRG,8"), "$VNRRG,8*4B\r\n");
  EXPECT_EQ(ascii_command("VNSIH,0.0"), "$VNSIH,0.0*48\r\n");
  EXPECT_EQ(ascii_command("VNWRG,75,1,04,05,0129,0010"), "$VNWRG,75,1,04,05,0129,0010*63\r\n");
}

TEST(Vn100Command, BinaryOutputRegisterForTheLoggerConfiguration) {
  // The LoggerWavesInIce configuration: IMU 0x003E + Attitude 0x003A at 800/80 = 10 Hz.
  const std::string cmd = write_binary_output(1, 1, 80, {0, 0, 0x003E, 0, 0x003A, 0});
  EXPECT_EQ(cmd.substr(0, cmd.find('*')), "$VNWRG,75,1,80,14,003E,003A");
  EXPECT_EQ(cmd.substr(cmd.find('*')), ascii_command("VNWRG,75,1,80,14,003E,003A").substr(cmd.find('*')));
  EXPECT_THROW((void)write_binary_output(4, 1, 80, {1, 0, 0, 0, 0, 0}), std::invalid_argument);
  EXPECT_THROW((void)write_binary_output(1, 1, 0, {1, 0, 0, 0, 0, 0}), std::invalid_argument);
  EXPECT_THROW((void)write_binary_output(1, 1, 80, {0, 0, 0, 0, 0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace trajroi::vn100
