// The pieces of `trajroi export` on their own: LZF round trips on data of every kind (the
// readers of the exported files check the format itself, export_test.cpp), and the LCM log
// reader on a log built here byte by byte as lcm-logger writes one, with another channel,
// bytes between events and a cut.
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "trajroi/cloud_io/lzf.hpp"
#include "trajroi/transport/lcm_log.hpp"

namespace {

using trajroi::cloud_io::lzf_compress;
using trajroi::cloud_io::lzf_decompress;

TEST(Lzf, EveryKindOfDataComesBackExactly) {
  std::mt19937 random(3);
  std::vector<std::vector<std::uint8_t>> cases;
  cases.emplace_back();            // empty
  cases.emplace_back(1, 7);        // one byte
  cases.emplace_back(100'000, 0);  // one long run
  std::vector<std::uint8_t> noise(70'000);
  for (auto& b : noise)
    b = static_cast<std::uint8_t>(random());
  cases.push_back(noise);            // incompressible
  std::vector<std::uint8_t> floats;  // a cloud's fields: slowly varying floats
  for (int i = 0; i < 50'000; ++i) {
    const float v = 12.5f + 0.001f * static_cast<float>(i % 977);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    floats.insert(floats.end(), p, p + 4);
  }
  cases.push_back(floats);
  std::vector<std::uint8_t> far;  // repeats just inside and beyond the 8 KiB window
  for (int i = 0; i < 40'000; ++i)
    far.push_back(static_cast<std::uint8_t>((i % 8192) * 31 + (i % 8193)));
  cases.push_back(far);
  for (const auto& data : cases) {
    const auto packed = lzf_compress(data);
    const auto back = lzf_decompress(packed, data.size());
    ASSERT_TRUE(back.has_value()) << data.size();
    EXPECT_EQ(*back, data) << data.size();
  }
  EXPECT_LT(lzf_compress(cases[2]).size(), 4'000U);
  EXPECT_LT(lzf_compress(floats).size(), floats.size() / 2);
}

TEST(Lzf, DamagedDataIsRefusedNotOverrun) {
  std::vector<std::uint8_t> data(5000, 1);
  auto packed = lzf_compress(data);
  EXPECT_FALSE(lzf_decompress(packed, data.size() - 1).has_value());
  EXPECT_FALSE(
      lzf_decompress(std::vector<std::uint8_t>{0xE0, 0xFF, 0xFF}, 100).has_value());   // reaches back before the start
  EXPECT_FALSE(lzf_decompress(std::vector<std::uint8_t>{31, 1, 2}, 100).has_value());  // a literal run cut short
}

void put_be(std::string& out, std::uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i)
    out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

std::string event(std::int64_t number, const std::string& channel, const std::string& data) {
  std::string e;
  put_be(e, 0xEDA1DA01, 4);
  put_be(e, static_cast<std::uint64_t>(number), 8);
  put_be(e, 1'700'000'000'000'000ULL + static_cast<std::uint64_t>(number), 8);
  put_be(e, channel.size(), 4);
  put_be(e, data.size(), 4);
  return e + channel + data;
}

TEST(LcmLogReader, EventsOtherBytesAndACut) {
  std::string log = event(0, "TRAJROI_POINTS", "abc") + "garbage!" + event(1, "OTHER", std::string(1000, 'x'));
  const std::size_t cut_at = log.size();
  log += event(2, "TRAJROI_POINTS", "0123456789").substr(0, 35);
  std::istringstream in(log);
  trajroi::transport::LcmLogReader reader(in);
  trajroi::transport::LcmLogEvent e;
  using Next = trajroi::transport::LcmLogReader::Next;
  ASSERT_EQ(reader.next(e), Next::kEvent);
  EXPECT_EQ(e.channel, "TRAJROI_POINTS");
  EXPECT_EQ(std::string(e.data.begin(), e.data.end()), "abc");
  ASSERT_EQ(reader.next(e), Next::kEvent);
  EXPECT_EQ(e.number, 1);
  EXPECT_EQ(e.channel, "OTHER");
  EXPECT_EQ(e.data.size(), 1000U);
  EXPECT_EQ(reader.skipped_bytes(), 8U);
  EXPECT_EQ(reader.next(e), Next::kCut);
  EXPECT_EQ(reader.event_offset(), cut_at);
  std::istringstream empty("");
  trajroi::transport::LcmLogReader none(empty);
  EXPECT_EQ(none.next(e), Next::kEnd);
}

}  // namespace
