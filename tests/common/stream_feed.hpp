#pragma once

// Feeding a byte stream to a framer the way a serial read loop does: in chunks.
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>

namespace trajroi::test {

inline std::span<const std::uint8_t> as_bytes(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// Feeds `bytes` in chunks of `chunk` bytes (0: all at once), then ends the stream.
template <class Framer, class Sink>
void feed_in_chunks(Framer& framer, std::span<const std::uint8_t> bytes, std::size_t chunk, Sink&& sink) {
  if (chunk == 0) chunk = std::max<std::size_t>(bytes.size(), 1);
  for (std::size_t at = 0; at < bytes.size(); at += chunk) {
    framer.feed(bytes.subspan(at, std::min(chunk, bytes.size() - at)), sink);
  }
  framer.finish(sink);
}

}  // namespace trajroi::test
