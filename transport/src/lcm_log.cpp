#include "trajroi/transport/lcm_log.hpp"

#include <array>

namespace trajroi::transport {

namespace {

constexpr std::uint32_t kSync = 0xEDA1DA01;
constexpr std::uint32_t kMaxChannel = 256;      // lcm-logger's names are at most 63 bytes
constexpr std::uint32_t kMaxData = 256U << 20;  // LCM's messages are at most 4 GB; logs of sane ones far less

std::uint64_t be(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i)
    v = (v << 8) | p[i];
  return v;
}

}  // namespace

bool LcmLogReader::read(void* to, std::size_t n) {
  in_.read(static_cast<char*>(to), static_cast<std::streamsize>(n));
  offset_ += static_cast<std::uint64_t>(in_.gcount());
  return static_cast<std::size_t>(in_.gcount()) == n;
}

LcmLogReader::Next LcmLogReader::next(LcmLogEvent& event) {
  std::array<std::uint8_t, 28> head{};
  for (;;) {
    // The sync word, byte by byte past anything else.
    std::size_t have = 0;
    event_offset_ = offset_;
    while (have < 4) {
      const int c = in_.get();
      if (c == std::char_traits<char>::eof()) return have == 0 ? Next::kEnd : Next::kCut;
      ++offset_;
      head[have++] = static_cast<std::uint8_t>(c);
      if (have == 4 && be(head.data(), 4) != kSync) {
        head[0] = head[1], head[1] = head[2], head[2] = head[3];
        have = 3;
        ++skipped_;
        event_offset_ = offset_ - 3;
      }
    }
    if (!read(head.data() + 4, 24)) return Next::kCut;
    const auto channel_length = static_cast<std::uint32_t>(be(head.data() + 20, 4));
    const auto data_length = static_cast<std::uint32_t>(be(head.data() + 24, 4));
    if (channel_length == 0 || channel_length > kMaxChannel || data_length > kMaxData) {
      skipped_ += 28;  // not an event after all: on to the next sync word
      continue;
    }
    event.number = static_cast<std::int64_t>(be(head.data() + 4, 8));
    event.timestamp_us = static_cast<std::int64_t>(be(head.data() + 12, 8));
    event.channel.resize(channel_length);
    event.data.resize(data_length);
    if (!read(event.channel.data(), channel_length) || !read(event.data.data(), data_length)) return Next::kCut;
    return Next::kEvent;
  }
}

}  // namespace trajroi::transport
