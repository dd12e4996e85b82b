#pragma once

// The checksums the serial protocols share: VectorNav's CRC-16 (CCITT, initial 0; its binary
// frames and its "*XXXX" ASCII form) and RTCM 10403.x's CRC-24Q.
#include <cstdint>
#include <span>

namespace trajroi::framing {

[[nodiscard]] constexpr std::uint16_t crc16_ccitt(std::span<const std::uint8_t> bytes) noexcept {
  std::uint16_t crc = 0;
  for (const std::uint8_t b : bytes) {
    crc = static_cast<std::uint16_t>((crc >> 8) | (crc << 8));
    crc ^= b;
    crc ^= static_cast<std::uint16_t>((crc & 0xFF) >> 4);
    crc ^= static_cast<std::uint16_t>(crc << 12);
    crc ^= static_cast<std::uint16_t>((crc & 0x00FF) << 5);
  }
  return crc;
}

// Polynomial 0x1864CFB, initial 0.
[[nodiscard]] constexpr std::uint32_t crc24q(std::span<const std::uint8_t> bytes) noexcept {
  std::uint32_t crc = 0;
  for (const std::uint8_t b : bytes) {
    crc ^= static_cast<std::uint32_t>(b) << 16;
    for (int i = 0; i < 8; ++i) {
      crc <<= 1;
      if ((crc & 0x1000000U) != 0) crc ^= 0x1864CFBU;
    }
  }
  return crc & 0xFFFFFFU;
}

}  // namespace trajroi::framing
