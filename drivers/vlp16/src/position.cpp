#include "trajroi/vlp16/position.hpp"

#include <array>
#include <charconv>
#include <chrono>
#include <cmath>

#include "trajroi/framing/utc.hpp"
#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr std::int64_t kNsPerUs = 1000;
constexpr std::int64_t kHour_ns = kHour_us * kNsPerUs;

int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool parse_int(std::string_view text, int& out) noexcept {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc{} && end == text.data() + text.size();
}

bool parse_double(std::string_view text, double& out) noexcept {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc{} && end == text.data() + text.size() && std::isfinite(out);
}

// NMEA angle "DDDMM.mmmm" with `degree_digits` digits of degrees; hemisphere `negative` sign.
bool parse_angle(std::string_view text, std::size_t degree_digits, std::string_view hemisphere, char positive,
                 char negative, double limit_deg, double& out) noexcept {
  int degrees = 0;
  double minutes = 0;
  if (text.size() < degree_digits + 2 || !parse_int(text.substr(0, degree_digits), degrees) ||
      !parse_double(text.substr(degree_digits), minutes) || minutes < 0 || minutes >= 60) {
    return false;
  }
  if (hemisphere.size() != 1 || (hemisphere[0] != positive && hemisphere[0] != negative)) return false;
  out = degrees + minutes / 60.0;
  if (out > limit_deg) return false;
  if (hemisphere[0] == negative) out = -out;
  return true;
}

}  // namespace

std::string_view to_string(PpsStatus status) noexcept {
  switch (status) {
    case PpsStatus::kAbsent:
      return "absent";
    case PpsStatus::kSynchronizing:
      return "synchronizing";
    case PpsStatus::kLocked:
      return "locked";
    case PpsStatus::kError:
      return "error";
    case PpsStatus::kUnknown:
      break;
  }
  return "unknown";
}

std::string_view to_string(NmeaError error) noexcept {
  switch (error) {
    case NmeaError::kNone:
      return "none";
    case NmeaError::kEmpty:
      return "empty";
    case NmeaError::kNotRmc:
      return "not_rmc";
    case NmeaError::kBadChecksum:
      return "bad_checksum";
    case NmeaError::kMalformed:
      return "malformed";
  }
  return "unknown";
}

NmeaError parse_rmc(std::string_view sentence, Rmc& out) noexcept {
  while (!sentence.empty() && (sentence.back() == '\n' || sentence.back() == '\r'))
    sentence.remove_suffix(1);
  if (sentence.empty()) return NmeaError::kEmpty;
  if (sentence.front() != '$') return NmeaError::kMalformed;
  const std::size_t star = sentence.rfind('*');
  if (star == std::string_view::npos || star + 3 != sentence.size()) return NmeaError::kBadChecksum;
  const int high = hex_value(sentence[star + 1]);
  const int low = hex_value(sentence[star + 2]);
  if (high < 0 || low < 0) return NmeaError::kBadChecksum;
  unsigned sum = 0;
  for (std::size_t i = 1; i < star; ++i)
    sum ^= static_cast<unsigned char>(sentence[i]);
  if (sum != static_cast<unsigned>(high * 16 + low)) return NmeaError::kBadChecksum;

  // $ttRMC,time,status,lat,N/S,lon,E/W,speed,course,date,…
  std::array<std::string_view, 10> field{};
  std::string_view body = sentence.substr(1, star - 1);
  std::size_t count = 0;
  while (count < field.size()) {
    const std::size_t comma = body.find(',');
    field[count++] = body.substr(0, comma);
    if (comma == std::string_view::npos) break;
    body.remove_prefix(comma + 1);
  }
  if (field[0].size() != 5 || field[0].substr(2) != "RMC") return NmeaError::kNotRmc;
  if (count < field.size()) return NmeaError::kMalformed;

  const std::string_view time = field[1];
  const std::string_view date = field[9];
  int hh = 0, mm = 0, day = 0, month = 0, yy = 0;
  double ss = 0;
  if (time.size() < 6 || !parse_int(time.substr(0, 2), hh) || !parse_int(time.substr(2, 2), mm) ||
      !parse_double(time.substr(4), ss) || hh > 23 || mm > 59 || ss < 0 || ss >= 61) {
    return NmeaError::kMalformed;
  }
  if (date.size() != 6 || !parse_int(date.substr(0, 2), day) || !parse_int(date.substr(2, 2), month) ||
      !parse_int(date.substr(4, 2), yy)) {
    return NmeaError::kMalformed;
  }
  const std::chrono::year_month_day ymd{std::chrono::year{yy < 80 ? 2000 + yy : 1900 + yy},
                                        std::chrono::month{static_cast<unsigned>(month)},
                                        std::chrono::day{static_cast<unsigned>(day)}};
  if (!ymd.ok()) return NmeaError::kMalformed;
  if (field[2] != "A" && field[2] != "V") return NmeaError::kMalformed;

  Rmc rmc;
  if (!parse_angle(field[3], 2, field[4], 'N', 'S', 90.0, rmc.latitude_deg) ||
      !parse_angle(field[5], 3, field[6], 'E', 'W', 180.0, rmc.longitude_deg)) {
    return NmeaError::kMalformed;
  }
  rmc.utc_ns = utc_ns_from_civil(ymd, hh * 3600 + mm * 60) + std::llround(ss * 1e9);
  rmc.valid = field[2] == "A";
  out = rmc;
  return NmeaError::kNone;
}

bool parse_position_packet(std::span<const std::uint8_t> payload, PositionPacket& out) noexcept {
  if (payload.size() != kPositionPacketBytes) return false;
  PositionPacket p;
  p.toh_us = read_u32(payload, kPositionTimestampOffset);
  const std::uint8_t pps = payload[kPpsStatusOffset];
  p.pps = pps <= 3 ? static_cast<PpsStatus>(pps) : PpsStatus::kUnknown;
  const auto nmea = payload.subspan(kNmeaOffset, kNmeaBytes);
  std::size_t length = 0;
  while (length < nmea.size() && nmea[length] != 0)
    ++length;
  const std::string_view sentence(reinterpret_cast<const char*>(nmea.data()), length);
  p.nmea = parse_rmc(sentence, p.rmc);
  out = p;
  return true;
}

bool TopOfHourClock::on_position(const PositionPacket& packet) noexcept {
  if (packet.pps != PpsStatus::kLocked || packet.nmea != NmeaError::kNone || !packet.rmc.valid) return false;
  // The RMC names the second the PPS marked; the sensor's timestamp of the same packet is a
  // little later, possibly already in the next hour.
  const std::int64_t rmc_hour = packet.rmc.utc_ns - packet.rmc.utc_ns % kHour_ns;
  std::int64_t hour = rmc_hour;
  const std::int64_t candidate = hour + static_cast<std::int64_t>(packet.toh_us) * kNsPerUs;
  if (candidate - packet.rmc.utc_ns > kHour_ns / 2) hour -= kHour_ns;
  if (packet.rmc.utc_ns - candidate > kHour_ns / 2) hour += kHour_ns;
  hour_start_ns_ = hour;
  reference_toh_us_ = packet.toh_us;
  return true;
}

std::optional<std::int64_t> TopOfHourClock::to_utc_ns(std::uint32_t toh_us) const noexcept {
  if (!hour_start_ns_) return std::nullopt;
  std::int64_t hour = *hour_start_ns_;
  const std::int64_t delta_us = static_cast<std::int64_t>(toh_us) - reference_toh_us_;
  if (delta_us < -kHour_us / 2) hour += kHour_ns;  // wrapped past the top of the hour
  if (delta_us > kHour_us / 2) hour -= kHour_ns;   // from just before the reference's hour
  return hour + static_cast<std::int64_t>(toh_us) * kNsPerUs;
}

}  // namespace trajroi::vlp16
