#pragma once

// VLP-16 packets built byte by byte for tests, independently of the decoder's accessors.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "trajroi/vlp16/packet.hpp"
#include "trajroi/vlp16/position.hpp"

namespace trajroi::vlp16 {

// A packet whose block n has azimuth (first + step · n) mod 36000, every distance 0.
inline std::vector<std::uint8_t> make_packet(std::uint16_t first_cdeg, std::uint16_t step_cdeg, ReturnMode mode,
                                             std::uint8_t product = 0x22, std::uint32_t toh_us = 123456) {
  std::vector<std::uint8_t> p(kDataPacketBytes, 0);
  const bool dual = mode == ReturnMode::kDual;
  for (std::size_t block = 0; block < kBlocks; ++block) {
    const std::size_t firing_index = dual ? block / 2 : block;
    const auto azimuth = static_cast<std::uint16_t>((first_cdeg + step_cdeg * firing_index) % 36000);
    p[block * 100] = 0xFF;
    p[block * 100 + 1] = 0xEE;
    p[block * 100 + 2] = static_cast<std::uint8_t>(azimuth & 0xFF);
    p[block * 100 + 3] = static_cast<std::uint8_t>(azimuth >> 8);
  }
  for (std::size_t k = 0; k < 4; ++k)
    p[1200 + k] = static_cast<std::uint8_t>(toh_us >> (8 * k));
  p[1204] = static_cast<std::uint8_t>(mode);
  p[1205] = product;
  return p;
}

inline void set_return(std::vector<std::uint8_t>& p, std::size_t block, std::size_t channel, std::uint16_t distance_2mm,
                       std::uint8_t reflectivity) {
  const std::size_t at = block * 100 + 4 + channel * 3;
  p[at] = static_cast<std::uint8_t>(distance_2mm & 0xFF);
  p[at + 1] = static_cast<std::uint8_t>(distance_2mm >> 8);
  p[at + 2] = reflectivity;
}

// A 512-byte position packet with this timestamp, PPS status byte and NMEA text.
inline std::vector<std::uint8_t> make_position_packet(std::uint32_t toh_us, std::uint8_t pps, const std::string& nmea) {
  std::vector<std::uint8_t> p(kPositionPacketBytes, 0);
  for (std::size_t k = 0; k < 4; ++k)
    p[198 + k] = static_cast<std::uint8_t>(toh_us >> (8 * k));
  p[202] = pps;
  for (std::size_t k = 0; k < nmea.size() && 206 + k < p.size(); ++k)
    p[206 + k] = static_cast<std::uint8_t>(nmea[k]);
  return p;
}

}  // namespace trajroi::vlp16
