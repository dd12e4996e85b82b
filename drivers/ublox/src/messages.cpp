#include "trajroi/ublox/messages.hpp"

#include <bit>
#include <limits>

#include "trajroi/framing/little_endian.hpp"
#include "trajroi/framing/utc.hpp"
#include "trajroi/ublox/config.hpp"

namespace trajroi::ublox {

using framing::le_i32;
using framing::le_i8;
using framing::le_u16;
using framing::le_u32;

std::string_view to_string(PayloadError error) noexcept {
  switch (error) {
    case PayloadError::kNone:
      return "none";
    case PayloadError::kWrongLength:
      return "wrong payload length";
    case PayloadError::kUnsupportedVersion:
      return "unsupported message version";
  }
  return "unknown";
}

std::string_view to_string(CarrierSolution solution) noexcept {
  switch (solution) {
    case CarrierSolution::kNone:
      return "none";
    case CarrierSolution::kFloat:
      return "float";
    case CarrierSolution::kFixed:
      return "fixed";
  }
  return "none";
}

namespace {

// Bits 6–7 of NAV-PVT flags and NAV-STATUS flags2; bits 3–4 of NAV-RELPOSNED flags. The
// reserved value 3 reads as "none": never claim a carrier solution the receiver did not.
CarrierSolution carrier_solution(unsigned bits) noexcept {
  switch (bits & 0x3U) {
    case 1:
      return CarrierSolution::kFloat;
    case 2:
      return CarrierSolution::kFixed;
    default:
      return CarrierSolution::kNone;
  }
}

template <class T>
Decoded<T> failure(PayloadError error) noexcept {
  Decoded<T> d;
  d.error = error;
  return d;
}

// The layouts of the messages trajroi both decodes and encodes are described once, as a walk
// over their fields (offset, width, bit): the decoder walks it with a FieldReader, the encoder
// with a FieldWriter over a zeroed payload, so the two cannot disagree.
struct FieldReader {
  std::span<const std::uint8_t> p;
  void u8(std::size_t at, std::uint8_t& v) const noexcept { v = p[at]; }
  void i8(std::size_t at, std::int8_t& v) const noexcept { v = le_i8(p, at); }
  void u16(std::size_t at, std::uint16_t& v) const noexcept { v = le_u16(p, at); }
  void u32(std::size_t at, std::uint32_t& v) const noexcept { v = le_u32(p, at); }
  void i32(std::size_t at, std::int32_t& v) const noexcept { v = le_i32(p, at); }
  void flag(std::size_t at, unsigned mask, bool& v) const noexcept { v = (p[at] & mask) != 0; }
  void carrier(std::size_t at, unsigned shift, CarrierSolution& v) const noexcept {
    v = carrier_solution(static_cast<unsigned>(p[at]) >> shift);
  }
};

struct FieldWriter {
  std::vector<std::uint8_t>& p;
  void put(std::size_t at, std::uint32_t v, std::size_t bytes) const {
    for (std::size_t k = 0; k < bytes; ++k)
      p[at + k] = static_cast<std::uint8_t>(v >> (8 * k));
  }
  void u8(std::size_t at, std::uint8_t v) const { p[at] = v; }
  void i8(std::size_t at, std::int8_t v) const { p[at] = std::bit_cast<std::uint8_t>(v); }
  void u16(std::size_t at, std::uint16_t v) const { put(at, v, 2); }
  void u32(std::size_t at, std::uint32_t v) const { put(at, v, 4); }
  void i32(std::size_t at, std::int32_t v) const { put(at, std::bit_cast<std::uint32_t>(v), 4); }
  void flag(std::size_t at, unsigned mask, bool v) const {
    if (v) p[at] = static_cast<std::uint8_t>(p[at] | mask);
  }
  void carrier(std::size_t at, unsigned shift, CarrierSolution v) const {
    p[at] = static_cast<std::uint8_t>(p[at] | (static_cast<unsigned>(v) << shift));
  }
};

// UBX-NAV-PVT, u-blox 8 / M8 interface description 32.17.17 (`size`: 92, or 84 for protocol 14).
template <class Io, class M>
void walk_nav_pvt(const Io& io, M& m, std::size_t size) {
  io.u32(0, m.itow_ms);
  io.u16(4, m.year);
  io.u8(6, m.month);
  io.u8(7, m.day);
  io.u8(8, m.hour);
  io.u8(9, m.minute);
  io.u8(10, m.second);
  io.flag(11, 0x01, m.valid_date);
  io.flag(11, 0x02, m.valid_time);
  io.flag(11, 0x04, m.fully_resolved);
  io.u32(12, m.time_accuracy_ns);
  io.i32(16, m.nano_ns);
  io.u8(20, m.fix_type_raw);
  io.flag(21, 0x01, m.gnss_fix_ok);
  io.flag(21, 0x02, m.diff_soln);
  io.flag(21, 0x20, m.head_veh_valid);
  io.carrier(21, 6, m.carr_soln);
  io.u8(23, m.num_sv);
  io.i32(24, m.lon_e7);
  io.i32(28, m.lat_e7);
  io.i32(32, m.height_mm);
  io.i32(36, m.hmsl_mm);
  io.u32(40, m.h_acc_mm);
  io.u32(44, m.v_acc_mm);
  io.i32(48, m.vel_n_mmps);
  io.i32(52, m.vel_e_mmps);
  io.i32(56, m.vel_d_mmps);
  io.i32(60, m.ground_speed_mmps);
  io.i32(64, m.head_mot_e5deg);
  io.u32(68, m.speed_acc_mmps);
  io.u32(72, m.head_acc_e5deg);
  io.u16(76, m.pdop_e2);
  io.flag(78, 0x01, m.invalid_llh);  // flags3
  if (size == NavPvt::kBytes) io.i32(84, m.head_veh_e5deg);
}

// UBX-NAV-HPPOSLLH, 32.17.11.
template <class Io, class M>
void walk_nav_hpposllh(const Io& io, M& m) {
  io.u8(0, m.version);
  io.flag(3, 0x01, m.invalid_llh);
  io.u32(4, m.itow_ms);
  io.i32(8, m.lon_e7);
  io.i32(12, m.lat_e7);
  io.i32(16, m.height_mm);
  io.i32(20, m.hmsl_mm);
  io.i8(24, m.lon_hp_e9);
  io.i8(25, m.lat_hp_e9);
  io.i8(26, m.height_hp_e4m);
  io.i8(27, m.hmsl_hp_e4m);
  io.u32(28, m.h_acc_e4m);
  io.u32(32, m.v_acc_e4m);
}

}  // namespace

FixType NavPvt::fix_type() const noexcept {
  return fix_type_raw <= 5 ? static_cast<FixType>(fix_type_raw) : FixType::kNoFix;
}

bool NavPvt::utc_valid() const noexcept {
  return valid_date && valid_time && utc_representable(date()) && hour < 24 && minute < 60 && second <= 60;
}

std::chrono::year_month_day NavPvt::date() const noexcept {
  return std::chrono::year{year} / std::chrono::month{month} / std::chrono::day{day};
}

std::int64_t NavPvt::utc_ns() const noexcept {
  const std::int64_t second_ns = utc_ns_from_civil(date(), hour * 3'600 + minute * 60 + second);
  return second_ns == std::numeric_limits<std::int64_t>::min() ? second_ns : second_ns + nano_ns;
}

Decoded<NavPvt> decode_nav_pvt(std::span<const std::uint8_t> p) noexcept {
  if (p.size() != NavPvt::kBytes && p.size() != NavPvt::kBytesProtocol14) {
    return failure<NavPvt>(PayloadError::kWrongLength);
  }
  Decoded<NavPvt> d;
  walk_nav_pvt(FieldReader{p}, d.value, p.size());
  d.value.has_head_veh = p.size() == NavPvt::kBytes;
  return d;
}

Decoded<NavHpposllh> decode_nav_hpposllh(std::span<const std::uint8_t> p) noexcept {
  if (p.size() != NavHpposllh::kBytes) return failure<NavHpposllh>(PayloadError::kWrongLength);
  if (p[0] > 1) return failure<NavHpposllh>(PayloadError::kUnsupportedVersion);
  Decoded<NavHpposllh> d;
  walk_nav_hpposllh(FieldReader{p}, d.value);
  return d;
}

Decoded<NavRelposned> decode_nav_relposned(std::span<const std::uint8_t> p) noexcept {
  constexpr std::size_t kVersion0Bytes = 40;
  constexpr std::size_t kVersion1Bytes = 64;
  if (p.empty()) return failure<NavRelposned>(PayloadError::kWrongLength);
  const std::uint8_t version = p[0];
  if (version > 1) return failure<NavRelposned>(PayloadError::kUnsupportedVersion);
  if (p.size() != (version == 0 ? kVersion0Bytes : kVersion1Bytes)) {
    return failure<NavRelposned>(PayloadError::kWrongLength);
  }
  Decoded<NavRelposned> d;
  NavRelposned& m = d.value;
  m.version = version;
  m.ref_station_id = le_u16(p, 2);
  m.itow_ms = le_u32(p, 4);
  m.rel_pos_n_cm = le_i32(p, 8);
  m.rel_pos_e_cm = le_i32(p, 12);
  m.rel_pos_d_cm = le_i32(p, 16);
  std::uint32_t flags = 0;
  if (version == 0) {
    m.rel_pos_hp_n_e4m = le_i8(p, 20);
    m.rel_pos_hp_e_e4m = le_i8(p, 21);
    m.rel_pos_hp_d_e4m = le_i8(p, 22);
    m.acc_n_e4m = le_u32(p, 24);
    m.acc_e_e4m = le_u32(p, 28);
    m.acc_d_e4m = le_u32(p, 32);
    flags = le_u32(p, 36);
  } else {
    m.rel_pos_length_cm = le_i32(p, 20);
    m.rel_pos_heading_e5deg = le_i32(p, 24);
    m.rel_pos_hp_n_e4m = le_i8(p, 32);
    m.rel_pos_hp_e_e4m = le_i8(p, 33);
    m.rel_pos_hp_d_e4m = le_i8(p, 34);
    m.rel_pos_hp_length_e4m = le_i8(p, 35);
    m.acc_n_e4m = le_u32(p, 36);
    m.acc_e_e4m = le_u32(p, 40);
    m.acc_d_e4m = le_u32(p, 44);
    m.acc_length_e4m = le_u32(p, 48);
    m.acc_heading_e5deg = le_u32(p, 52);
    flags = le_u32(p, 60);
    m.heading_valid = (flags & 0x100U) != 0;
  }
  m.gnss_fix_ok = (flags & 0x01U) != 0;
  m.diff_soln = (flags & 0x02U) != 0;
  m.rel_pos_valid = (flags & 0x04U) != 0;
  m.carr_soln = carrier_solution(flags >> 3U);
  m.is_moving = (flags & 0x20U) != 0;
  m.ref_pos_miss = (flags & 0x40U) != 0;
  m.ref_obs_miss = (flags & 0x80U) != 0;
  return d;
}

Decoded<NavCov> decode_nav_cov(std::span<const std::uint8_t> p) noexcept {
  if (p.size() != NavCov::kBytes) return failure<NavCov>(PayloadError::kWrongLength);
  Decoded<NavCov> d;
  NavCov& m = d.value;
  m.itow_ms = le_u32(p, 0);
  m.version = p[4];
  m.pos_cov_valid = p[5] != 0;
  m.vel_cov_valid = p[6] != 0;
  for (std::size_t i = 0; i < 6; ++i) {
    m.pos_cov_ned[i] = framing::le_f32(p, 16 + 4 * i);
    m.vel_cov_ned[i] = framing::le_f32(p, 40 + 4 * i);
  }
  return d;
}

Decoded<NavStatus> decode_nav_status(std::span<const std::uint8_t> p) noexcept {
  if (p.size() != NavStatus::kBytes) return failure<NavStatus>(PayloadError::kWrongLength);
  Decoded<NavStatus> d;
  NavStatus& m = d.value;
  m.itow_ms = le_u32(p, 0);
  m.gps_fix = p[4];
  m.gps_fix_ok = (p[5] & 0x01) != 0;
  m.diff_soln = (p[5] & 0x02) != 0;
  m.week_set = (p[5] & 0x04) != 0;
  m.tow_set = (p[5] & 0x08) != 0;
  m.carr_soln = carrier_solution(p[7] >> 6U);
  m.ttff_ms = le_u32(p, 8);
  m.msss_ms = le_u32(p, 12);
  return d;
}

Decoded<Ack> decode_ack(std::uint8_t msg_id, std::span<const std::uint8_t> p) noexcept {
  if (p.size() != Ack::kBytes) return failure<Ack>(PayloadError::kWrongLength);
  Decoded<Ack> d;
  d.value.acknowledged = msg_id == kIdAckAck;
  d.value.msg_class = p[0];
  d.value.msg_id = p[1];
  return d;
}

std::vector<std::uint8_t> encode_nav_pvt(const NavPvt& m) {
  std::vector<std::uint8_t> p(NavPvt::kBytes, 0);
  walk_nav_pvt(FieldWriter{p}, m, NavPvt::kBytes);
  return encode_frame(kClassNav, kIdNavPvt, p);
}

std::vector<std::uint8_t> encode_nav_hpposllh(const NavHpposllh& m) {
  std::vector<std::uint8_t> p(NavHpposllh::kBytes, 0);
  walk_nav_hpposllh(FieldWriter{p}, m);
  return encode_frame(kClassNav, kIdNavHpposllh, p);
}

}  // namespace trajroi::ublox
