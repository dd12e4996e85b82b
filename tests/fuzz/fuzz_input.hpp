// Helpers shared by the fuzz targets: an input seen as a byte stream cut into pieces (as a
// serial port or a socket delivers it), and as text.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace trajroi::fuzz {

// The first byte chooses the piece size (1 … 256); the rest is the stream.
template <typename Piece>
void for_each_piece(const std::uint8_t* data, std::size_t size, Piece piece) {
  if (size == 0) return;
  const std::size_t step = static_cast<std::size_t>(data[0]) + 1;
  const std::span<const std::uint8_t> stream(data + 1, size - 1);
  for (std::size_t at = 0; at < stream.size(); at += step) {
    piece(stream.subspan(at, step < stream.size() - at ? step : stream.size() - at));
  }
}

// Datagrams: each is a 2-byte little-endian length (the top bit picks the second port) and
// that many bytes, as many as the input holds.
template <typename Datagram>
void for_each_datagram(const std::uint8_t* data, std::size_t size, Datagram datagram) {
  std::size_t at = 0;
  while (at + 2 <= size) {
    const unsigned header = static_cast<unsigned>(data[at]) | static_cast<unsigned>(data[at + 1]) << 8U;
    at += 2;
    const std::size_t length = header & 0x7FFFU;
    const std::size_t n = length < size - at ? length : size - at;
    datagram((header & 0x8000U) != 0, std::span<const std::uint8_t>(data + at, n));
    at += n;
  }
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace trajroi::fuzz
