#pragma once

// The VLP-16 position packet (VLP-16 User Manual, "Position Packet"): the 512-byte UDP
// payload on port 8308 carrying the sensor's top-of-hour timestamp, the PPS status and the
// NMEA $GPRMC sentence it received from a GPS. Pure: bytes in, values out.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {

inline constexpr std::size_t kPositionPacketBytes = 512;
inline constexpr std::size_t kPositionTimestampOffset = 198;  // µs past the hour, uint32 LE
inline constexpr std::size_t kPpsStatusOffset = 202;
inline constexpr std::size_t kNmeaOffset = 206;
inline constexpr std::size_t kNmeaBytes = 128;  // NUL padded

enum class PpsStatus : std::uint8_t { kAbsent = 0, kSynchronizing = 1, kLocked = 2, kError = 3, kUnknown = 0xFF };
[[nodiscard]] std::string_view to_string(PpsStatus status) noexcept;

// Why the NMEA field of a position packet gave no RMC fix.
enum class NmeaError : std::uint8_t {
  kNone,
  kEmpty,        // no sentence (no GPS connected)
  kNotRmc,       // a sentence, but not $xxRMC
  kBadChecksum,  // missing '*hh' or the XOR does not match
  kMalformed,    // a field is missing or out of range
};
inline constexpr std::size_t kNmeaErrorCount = 5;
[[nodiscard]] std::string_view to_string(NmeaError error) noexcept;

// The recommended minimum fix: time, validity and position.
struct Rmc {
  std::int64_t utc_ns = 0;   // since 1970-01-01 UTC
  bool valid = false;        // status 'A'
  double latitude_deg = 0;   // north positive
  double longitude_deg = 0;  // east positive
};

// Parses one NMEA RMC sentence (any talker: GP, GN, …), checksum verified. Date years 80–99
// are 19yy, 00–79 are 20yy.
[[nodiscard]] NmeaError parse_rmc(std::string_view sentence, Rmc& out) noexcept;

struct PositionPacket {
  std::uint32_t toh_us = 0;  // the packet's own top-of-hour timestamp
  PpsStatus pps = PpsStatus::kAbsent;
  NmeaError nmea = NmeaError::kEmpty;
  Rmc rmc;  // meaningful when nmea == kNone
};

// False (and `out` untouched) unless the payload is exactly 512 bytes.
[[nodiscard]] bool parse_position_packet(std::span<const std::uint8_t> payload, PositionPacket& out) noexcept;

// Turns top-of-hour timestamps into UTC once a position packet has tied the sensor clock to
// a valid RMC (with the PPS locked, so that the top of the sensor's hour is UTC's). The hour
// is taken from the RMC; timestamps within half an hour either side of the reference are
// placed in the neighbouring hour when they wrapped.
class TopOfHourClock {
 public:
  // Returns true when the packet (PPS locked, valid RMC) became the reference.
  bool on_position(const PositionPacket& packet) noexcept;
  [[nodiscard]] bool locked() const noexcept { return hour_start_ns_.has_value(); }
  // UTC of a top-of-hour timestamp, when locked.
  [[nodiscard]] std::optional<std::int64_t> to_utc_ns(std::uint32_t toh_us) const noexcept;

 private:
  std::optional<std::int64_t> hour_start_ns_;  // UTC of the reference packet's hour
  std::uint32_t reference_toh_us_ = 0;
};

}  // namespace trajroi::vlp16
