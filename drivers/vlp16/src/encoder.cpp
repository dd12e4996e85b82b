#include "trajroi/vlp16/encoder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "trajroi/framing/little_endian.hpp"

namespace trajroi::vlp16 {
namespace {

void put_echo(std::span<std::uint8_t> p, std::size_t block, std::size_t channel, const Echo& echo) {
  const std::size_t at = block * kBlockBytes + 4 + channel * 3;
  framing::store_le_u16(p, at, echo.distance_2mm);
  p[at + 2] = echo.reflectivity;
}

void put_block(std::span<std::uint8_t> p, std::size_t block, std::uint16_t azimuth_cdeg,
               const std::array<Echo, kChannelsPerBlock>& echoes) {
  framing::store_le_u16(p, block * kBlockBytes, kBlockFlag);
  framing::store_le_u16(p, block * kBlockBytes + 2, azimuth_cdeg);
  for (std::size_t channel = 0; channel < kChannelsPerBlock; ++channel)
    put_echo(p, block, channel, echoes[channel]);
}

// "ddmm.mmmmm" (or "dddmm.mmmmm") of |angle|, rounded to 1e-5 minute with the carry done in
// integers so that 59.999996' never prints as 60.00000'.
void append_angle(std::string& out, double angle_deg, int degree_digits) {
  constexpr long long kUnitsPerMinute = 100'000;
  const long long units = std::llround(std::abs(angle_deg) * 60.0 * kUnitsPerMinute);
  const long long degrees = units / (60 * kUnitsPerMinute);
  const long long minute_units = units % (60 * kUnitsPerMinute);
  char text[32];
  std::snprintf(text, sizeof text, "%0*lld%02lld.%05lld", degree_digits, degrees, minute_units / kUnitsPerMinute,
                minute_units % kUnitsPerMinute);
  out += text;
}

}  // namespace

void encode_data_packet(const DataPacketHeader& header, std::span<const FiringBlock> blocks,
                        std::span<std::uint8_t, kDataPacketBytes> out) {
  if (header.mode != ReturnMode::kStrongest && header.mode != ReturnMode::kLast && header.mode != ReturnMode::kDual) {
    throw std::invalid_argument("VLP-16 encoder: unknown return mode");
  }
  if (blocks.size() != firing_blocks_per_packet(header.mode)) {
    throw std::invalid_argument("VLP-16 encoder: " + std::to_string(blocks.size()) + " blocks for a packet of " +
                                std::to_string(firing_blocks_per_packet(header.mode)));
  }
  if (header.toh_us >= static_cast<std::uint64_t>(kHour_us)) {
    throw std::invalid_argument("VLP-16 encoder: timestamp past the hour");
  }
  for (const FiringBlock& block : blocks) {
    if (block.azimuth_cdeg >= kAzimuthLimit)
      throw std::invalid_argument("VLP-16 encoder: azimuth of 360 degrees or more");
  }
  const std::span<std::uint8_t> p(out);
  std::fill(p.begin(), p.end(), std::uint8_t{0});
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const FiringBlock& block = blocks[i];
    switch (header.mode) {
      case ReturnMode::kStrongest:
        put_block(p, i, block.azimuth_cdeg, block.strongest);
        break;
      case ReturnMode::kLast:
        put_block(p, i, block.azimuth_cdeg, block.last);
        break;
      case ReturnMode::kDual:
        put_block(p, 2 * i, block.azimuth_cdeg, block.last);
        put_block(p, 2 * i + 1, block.azimuth_cdeg, block.strongest);
        break;
    }
  }
  framing::store_le_u32(p, kTimestampOffset, header.toh_us);
  p[kReturnModeOffset] = static_cast<std::uint8_t>(header.mode);
  p[kProductIdOffset] = header.product;
}

void encode_position_packet(std::uint32_t toh_us, PpsStatus pps, std::string_view nmea,
                            std::span<std::uint8_t, kPositionPacketBytes> out) {
  if (nmea.size() > kNmeaBytes) throw std::invalid_argument("VLP-16 encoder: NMEA sentence longer than 128 bytes");
  if (toh_us >= static_cast<std::uint64_t>(kHour_us))
    throw std::invalid_argument("VLP-16 encoder: timestamp past the hour");
  const std::span<std::uint8_t> p(out);
  std::fill(p.begin(), p.end(), std::uint8_t{0});
  framing::store_le_u32(p, kPositionTimestampOffset, toh_us);
  p[kPpsStatusOffset] = static_cast<std::uint8_t>(pps);
  std::copy(nmea.begin(), nmea.end(), p.begin() + static_cast<std::ptrdiff_t>(kNmeaOffset));
}

std::string format_rmc(const Rmc& fix, double speed_knots, double course_deg) {
  namespace c = std::chrono;
  if (!(std::abs(fix.latitude_deg) <= 90.0) || !(std::abs(fix.longitude_deg) <= 180.0)) {
    throw std::invalid_argument("RMC: position out of range");
  }
  using centiseconds = c::duration<std::int64_t, std::centi>;
  const c::sys_time<centiseconds> centis =
      c::round<centiseconds>(c::sys_time<c::nanoseconds>{c::nanoseconds{fix.utc_ns}});
  const auto day = c::floor<c::days>(centis);
  const c::year_month_day ymd{day};
  const int year = int{ymd.year()};
  if (year < 1980 || year > 2079) throw std::invalid_argument("RMC: year outside 1980 … 2079");
  const c::hh_mm_ss hms{centis - day};

  std::string s = "$GPRMC,";
  char field[48];
  std::snprintf(field, sizeof field, "%02ld%02ld%02ld.%02ld,%c,", static_cast<long>(hms.hours().count()),
                static_cast<long>(hms.minutes().count()), static_cast<long>(hms.seconds().count()),
                static_cast<long>(hms.subseconds().count()), fix.valid ? 'A' : 'V');
  s += field;
  append_angle(s, fix.latitude_deg, 2);
  s += fix.latitude_deg < 0 ? ",S," : ",N,";
  append_angle(s, fix.longitude_deg, 3);
  s += fix.longitude_deg < 0 ? ",W," : ",E,";
  std::snprintf(field, sizeof field, "%05.1f,%05.1f,%02u%02u%02d,,,%c", std::max(speed_knots, 0.0),
                std::fmod(std::fmod(course_deg, 360.0) + 360.0, 360.0), unsigned{ymd.day()}, unsigned{ymd.month()},
                year % 100, fix.valid ? 'A' : 'N');
  s += field;
  unsigned checksum = 0;
  for (std::size_t i = 1; i < s.size(); ++i)
    checksum ^= static_cast<unsigned char>(s[i]);
  std::snprintf(field, sizeof field, "*%02X\r\n", checksum);
  s += field;
  return s;
}

}  // namespace trajroi::vlp16
