#pragma once

// The events of an LCM log as lcm-logger (and an LCM `file://` URL) write them: a sync word
// 0xEDA1DA01, the event number, its time (µs), the channel's and the data's lengths (all big
// endian), the channel, the data. A log cut short ends in kCut with the byte where its last,
// incomplete event began; bytes that are not an event are skipped up to the next sync word
// and counted, as liblcm's reader does.
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

namespace trajroi::transport {

struct LcmLogEvent {
  std::int64_t number = 0;
  std::int64_t timestamp_us = 0;
  std::string channel;
  std::vector<std::uint8_t> data;
};

class LcmLogReader {
 public:
  explicit LcmLogReader(std::istream& in) : in_(in) {}
  enum class Next : std::uint8_t { kEvent, kEnd, kCut };
  Next next(LcmLogEvent& event);
  // Where the event handed out (or the cut one) began.
  [[nodiscard]] std::uint64_t event_offset() const noexcept { return event_offset_; }
  [[nodiscard]] std::uint64_t skipped_bytes() const noexcept { return skipped_; }

 private:
  bool read(void* to, std::size_t n);
  std::istream& in_;
  std::uint64_t offset_ = 0, event_offset_ = 0, skipped_ = 0;
};

}  // namespace trajroi::transport
