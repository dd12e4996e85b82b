#pragma once

// The VLP-16 data packet (VLP-16 User Manual, "Sensor Data"): the 1206-byte UDP payload on
// port 2368, described as named offsets and little-endian accessors over bytes. No struct
// casts: every field is read with byte shifts.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "trajroi/framing/little_endian.hpp"

namespace trajroi::vlp16 {

inline constexpr std::size_t kDataPacketBytes = 1206;
inline constexpr std::size_t kBlocks = 12;
inline constexpr std::size_t kBlockBytes = 100;  // flag 2 + azimuth 2 + 32 × 3
inline constexpr std::size_t kLasers = 16;
inline constexpr std::size_t kFiringsPerBlock = 2;  // two firing sequences of 16 lasers
inline constexpr std::size_t kPointsPerPacket = kBlocks * kFiringsPerBlock * kLasers;  // at most (384)
inline constexpr std::size_t kTimestampOffset = 1200;                                  // µs past the hour, uint32 LE
inline constexpr std::size_t kReturnModeOffset = 1204;
inline constexpr std::size_t kProductIdOffset = 1205;
inline constexpr std::uint16_t kBlockFlag = 0xEEFF;    // bytes FF EE, read little-endian
inline constexpr std::uint16_t kAzimuthLimit = 36000;  // hundredths of a degree
inline constexpr double kDistanceUnit_m = 0.002;
inline constexpr double kLaserPeriod_us = 2.304;                    // between two lasers of one firing
inline constexpr double kFiringCycle_us = 55.296;                   // one firing sequence, recharge included
inline constexpr double kBlockDuration_us = 2.0 * kFiringCycle_us;  // 110.592: a block's two sequences
// The same in whole nanoseconds (exact: the manual's figures are multiples of 1 ns).
inline constexpr std::int64_t kLaserPeriod_ns = 2'304;
inline constexpr std::int64_t kFiringCycle_ns = 55'296;
inline constexpr std::int64_t kBlockDuration_ns = 2 * kFiringCycle_ns;
inline constexpr std::int64_t kHour_us = 3'600'000'000;  // timestamps count µs past the hour

enum class ReturnMode : std::uint8_t { kStrongest = 0x37, kLast = 0x38, kDual = 0x39 };
inline constexpr std::uint8_t kProductVlp16 = 0x22;
inline constexpr std::uint8_t kProductHdl32e = 0x21;
inline constexpr std::uint8_t kProductPuckHiRes = 0x24;
inline constexpr std::uint8_t kProductVlp32c = 0x28;

// Why a data packet was not decoded. Counted by the caller, never thrown.
enum class PacketError : std::uint8_t {
  kNone,
  kWrongSize,
  kBadBlockFlag,
  kAzimuthOutOfRange,
  kUnknownReturnMode,
  kUnsupportedProduct,
};
inline constexpr std::size_t kPacketErrorCount = 6;
[[nodiscard]] std::string_view to_string(PacketError error) noexcept;

// Little-endian readers shared with the serial protocols.
inline constexpr auto& read_u16 = framing::le_u16;
inline constexpr auto& read_u32 = framing::le_u32;

// Field accessors; the packet must have been validated (validate_data_packet() == kNone).
// The firmware writes 36000 for a block that fires exactly at the wrap, before it writes 0:
// that is 0° (ros-drivers/velodyne and VeloView take the azimuth modulo 36000).
[[nodiscard]] inline std::uint16_t block_azimuth(std::span<const std::uint8_t> p, std::size_t block) noexcept {
  const std::uint16_t raw = read_u16(p, block * kBlockBytes + 2);
  return raw == kAzimuthLimit ? std::uint16_t{0} : raw;
}
// Channel 0 … 31 of a block: firing sequence channel / 16, laser channel % 16.
[[nodiscard]] inline std::uint16_t channel_distance(std::span<const std::uint8_t> p, std::size_t block,
                                                    std::size_t channel) noexcept {
  return read_u16(p, block * kBlockBytes + 4 + channel * 3);
}
[[nodiscard]] inline std::uint8_t channel_reflectivity(std::span<const std::uint8_t> p, std::size_t block,
                                                       std::size_t channel) noexcept {
  return p[block * kBlockBytes + 4 + channel * 3 + 2];
}
[[nodiscard]] inline std::uint32_t timestamp_us(std::span<const std::uint8_t> p) noexcept {
  return read_u32(p, kTimestampOffset);
}
[[nodiscard]] inline std::uint8_t return_mode_byte(std::span<const std::uint8_t> p) noexcept {
  return p[kReturnModeOffset];
}
[[nodiscard]] inline std::uint8_t product_id(std::span<const std::uint8_t> p) noexcept {
  return p[kProductIdOffset];
}

// The azimuth advance from `from` to `to`, hundredths of a degree, across the 0/360 wrap.
[[nodiscard]] inline std::uint32_t azimuth_gap(std::uint16_t from, std::uint16_t to) noexcept {
  return (static_cast<std::uint32_t>(to) + kAzimuthLimit - from) % kAzimuthLimit;
}

// Channel 0 … 31 of a block: its firing time after the block's first, as a fraction of the
// block's duration — the weight of the azimuth advance that a channel's azimuth takes.
[[nodiscard]] inline double azimuth_fraction(std::size_t channel) noexcept {
  return (static_cast<double>(channel / kLasers) * kFiringCycle_us +
          static_cast<double>(channel % kLasers) * kLaserPeriod_us) /
         kBlockDuration_us;
}

// `to − from` for two top-of-hour timestamps, across the hour wrap: in [−½ h, ½ h).
[[nodiscard]] inline std::int64_t toh_delta_us(std::uint32_t from, std::uint32_t to) noexcept {
  const std::int64_t delta = (static_cast<std::int64_t>(to) - from + kHour_us + kHour_us / 2) % kHour_us;
  return delta - kHour_us / 2;
}

// Checks size, every block flag and azimuth, the return mode and the product id. The ids of
// the models trajroi decodes pass (0x22 VLP-16 and Puck LITE, 0x24 Puck Hi-Res, 0x28 VLP-32C,
// 0x21 HDL-32E or early VLP-16 firmware: ModelCheck decides by timing); any other id is
// kUnsupportedProduct.
[[nodiscard]] PacketError validate_data_packet(std::span<const std::uint8_t> packet) noexcept;

// A readable name for a product id byte ("VLP-32C" for 0x28), for rejection messages.
[[nodiscard]] std::string_view product_name(std::uint8_t id) noexcept;

}  // namespace trajroi::vlp16
