#pragma once

// Encoding VLP-16 data and position packets: the exact inverse of the decoders, used by the
// scenario simulator to produce the bytes a real sensor sends. Pure: values in, bytes out.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "trajroi/vlp16/packet.hpp"
#include "trajroi/vlp16/position.hpp"

namespace trajroi::vlp16 {

inline constexpr std::size_t kChannelsPerBlock = kFiringsPerBlock * kLasers;  // 32

// One return of one laser: the distance in the packet's 2 mm units (0 = no return) and the
// calibrated reflectivity.
struct Echo {
  std::uint16_t distance_2mm = 0;
  std::uint8_t reflectivity = 0;
  bool operator==(const Echo&) const = default;
};

// The returns of one block's 110.592 µs: two firing sequences of the 16 lasers, channel =
// sequence · 16 + laser, and the azimuth (hundredths of a degree) of its first firing.
struct FiringBlock {
  std::uint16_t azimuth_cdeg = 0;
  std::array<Echo, kChannelsPerBlock> strongest{};  // strongest mode; dual: the odd block
  std::array<Echo, kChannelsPerBlock> last{};       // last mode; dual: the even block
};

struct DataPacketHeader {
  ReturnMode mode = ReturnMode::kStrongest;
  std::uint8_t product = kProductVlp16;
  std::uint32_t toh_us = 0;  // µs past the hour of the packet's first firing, < 3.6e9
};

// Blocks of returns one packet carries: 12 in the single-return modes; 6 in dual mode, where
// each fills a block pair (last return in the even block, strongest in the odd one; when
// they are the same return a real sensor puts the second strongest in the odd block, which
// is the caller's choice to make).
[[nodiscard]] constexpr std::size_t firing_blocks_per_packet(ReturnMode mode) noexcept {
  return mode == ReturnMode::kDual ? kBlocks / 2 : kBlocks;
}

// Writes the 1206-byte payload. Throws std::invalid_argument when the number of blocks does
// not match the mode, an azimuth is 36000 or more, the timestamp is an hour or more, or the
// mode is not one of the three. validate_data_packet() accepts every packet written.
void encode_data_packet(const DataPacketHeader& header, std::span<const FiringBlock> blocks,
                        std::span<std::uint8_t, kDataPacketBytes> out);

// Writes the 512-byte position packet: timestamp, PPS status and the NMEA sentence
// (NUL-padded to 128 bytes; everything else zero). Throws std::invalid_argument for a
// sentence longer than 128 bytes or a timestamp of an hour or more.
void encode_position_packet(std::uint32_t toh_us, PpsStatus pps, std::string_view nmea,
                            std::span<std::uint8_t, kPositionPacketBytes> out);

// The $GPRMC sentence of a fix, as a GPS feeding the sensor sends it (time to the
// centisecond, positions to 1e-5 minute ≈ 2 cm, speed in knots, course in degrees, checksum
// and CR LF). parse_rmc() reads it back. Throws std::invalid_argument for a year outside
// 1980 … 2079 (two-digit years) or a position out of range.
[[nodiscard]] std::string format_rmc(const Rmc& fix, double speed_knots = 0.0, double course_deg = 0.0);

}  // namespace trajroi::vlp16
