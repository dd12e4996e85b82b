#pragma once

// Little-endian field readers and writers over byte spans, for wire formats described as
// named offsets. Reads assume the caller checked the span is long enough.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace trajroi::framing {

namespace detail {
// The bytes at `at` as the host stores a T: one unaligned load.
template <typename T>
[[nodiscard]] inline T host_load(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  T v;
  std::memcpy(&v, b.subspan(at, sizeof v).data(), sizeof v);
  return v;
}
}  // namespace detail

// On a little-endian host one unaligned load (GCC 12 leaves the bytes' shifts and ors as they
// are: four instructions for a u16 in the VLP-16 decoder's inner loop).
[[nodiscard]] inline std::uint16_t le_u16(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  if constexpr (std::endian::native == std::endian::little) return detail::host_load<std::uint16_t>(b, at);
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}
[[nodiscard]] inline std::uint32_t le_u32(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  if constexpr (std::endian::native == std::endian::little) return detail::host_load<std::uint32_t>(b, at);
  return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
         (static_cast<std::uint32_t>(b[at + 2]) << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}
[[nodiscard]] inline std::uint64_t le_u64(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return static_cast<std::uint64_t>(le_u32(b, at)) | (static_cast<std::uint64_t>(le_u32(b, at + 4)) << 32);
}
[[nodiscard]] inline std::int8_t le_i8(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return std::bit_cast<std::int8_t>(b[at]);
}
[[nodiscard]] inline std::int16_t le_i16(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return std::bit_cast<std::int16_t>(le_u16(b, at));
}
[[nodiscard]] inline std::int32_t le_i32(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return std::bit_cast<std::int32_t>(le_u32(b, at));
}
[[nodiscard]] inline float le_f32(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return std::bit_cast<float>(le_u32(b, at));
}
[[nodiscard]] inline double le_f64(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return std::bit_cast<double>(le_u64(b, at));
}

inline void put_le_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}
inline void put_le_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  put_le_u16(out, static_cast<std::uint16_t>(v));
  put_le_u16(out, static_cast<std::uint16_t>(v >> 16));
}
inline void put_le_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  put_le_u32(out, static_cast<std::uint32_t>(v));
  put_le_u32(out, static_cast<std::uint32_t>(v >> 32));
}

// In-place writers at an offset; the caller checked the span is long enough.
inline void store_le_u16(std::span<std::uint8_t> b, std::size_t at, std::uint16_t v) noexcept {
  b[at] = static_cast<std::uint8_t>(v);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
inline void store_le_u32(std::span<std::uint8_t> b, std::size_t at, std::uint32_t v) noexcept {
  store_le_u16(b, at, static_cast<std::uint16_t>(v));
  store_le_u16(b, at + 2, static_cast<std::uint16_t>(v >> 16));
}

}  // namespace trajroi::framing
