#include "trajroi/ublox/messages.hpp"

#include <bit>
#include <limits>

#include "trajroi/framing/little_endian.hpp"
#include "trajroi/ublox/config.hpp"
#include "trajroi/framing/utc.hpp"

namespace trajroi::ublox {

using framing::le_i32;
using framing::le_i8;
using framing::le_u16;
using framing::le_u32;

std::string_view to_string(PayloadError error) noexcept {
  switch (error) {
    case PayloadError::kNone: return "none";
    case PayloadError::kWrongLength: return "wrong payload length";
    case PayloadError::kUnsupportedVersion: return "unsupported message version";
  }
  return "unknown";
}

std::string_view to_string(CarrierSolution solution) noexcept {
  switch (solution) {
    case CarrierSolution::kNone: return "none";
    case CarrierSolution::kFloat: return "float";
    case CarrierSolution::kFixed: return "fixed";
  }
  return "none";
}

namespace {

// Bits 6–7 of NAV-PVT flags and NAV-STATUS flags2; bits 3–4 of NAV-RELPOSNED flags. The
// reserved value 3 reads as "none": never claim a carrier solution the receiver did not.
CarrierSolution carrier_solution(unsigned bits) noexcept {
  switch (bits & 0x3U) {
    case 1: return CarrierSolution::kFloat;
    case 2: return CarrierSolution::kFixed;
    default: return CarrierSolution::kNone;
  }
}

template <class T>
Decoded<T> failure(PayloadError error) noexcept {
  Decoded<T> d;
  d.error = error;
  return d;
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
  NavPvt& m = d.value;
  m.itow_ms = le_u32(p, 0);
  m.year = le_u16(p, 4);
  m.month = p[6];
  m.day = p[7];
  m.hour = p[8];
  m.minute = p[9];
  m.second = p[10];
  m.valid_date = (p[11] & 0x01) != 0;
  m.valid_time = (p[11] & 0x02) != 0;
  m.fully_resolved = (p[11] & 0x04) != 0;
  m.time_accuracy_ns = le_u32(p, 12);
  m.nano_ns = le_i32(p, 16);
  m.fix_type_raw = p[20];
  m.gnss_fix_ok = (p[21] & 0x01) != 0;
  m.diff_soln = (p[21] & 0x02) != 0;
  m.head_veh_valid = (p[21] & 0x20) != 0;
  m.carr_soln = carrier_solution(p[21] >> 6U);
  m.num_sv = p[23];
  m.lon_e7 = le_i32(p, 24);
  m.lat_e7 = le_i32(p, 28);
  m.height_mm = le_i32(p, 32);
  m.hmsl_mm = le_i32(p, 36);
  m.h_acc_mm = le_u32(p, 40);
  m.v_acc_mm = le_u32(p, 44);
  m.vel_n_mmps = le_i32(p, 48);
  m.vel_e_mmps = le_i32(p, 52);
  m.vel_d_mmps = le_i32(p, 56);
  m.ground_speed_mmps = le_i32(p, 60);
  m.head_mot_e5deg = le_i32(p, 64);
  m.speed_acc_mmps = le_u32(p, 68);
  m.head_acc_e5deg = le_u32(p, 72);
  m.pdop_e2 = le_u16(p, 76);
  m.invalid_llh = (p[78] & 0x01) != 0;
  if (p.size() == NavPvt::kBytes) {
    m.has_head_veh = true;
    m.head_veh_e5deg = le_i32(p, 84);
  }
  return d;
}

Decoded<NavHpposllh> decode_nav_hpposllh(std::span<const std::uint8_t> p) noexcept {
  if (p.size() != NavHpposllh::kBytes) return failure<NavHpposllh>(PayloadError::kWrongLength);
  if (p[0] > 1) return failure<NavHpposllh>(PayloadError::kUnsupportedVersion);
  Decoded<NavHpposllh> d;
  NavHpposllh& m = d.value;
  m.version = p[0];
  m.invalid_llh = (p[3] & 0x01) != 0;
  m.itow_ms = le_u32(p, 4);
  m.lon_e7 = le_i32(p, 8);
  m.lat_e7 = le_i32(p, 12);
  m.height_mm = le_i32(p, 16);
  m.hmsl_mm = le_i32(p, 20);
  m.lon_hp_e9 = le_i8(p, 24);
  m.lat_hp_e9 = le_i8(p, 25);
  m.height_hp_e4m = le_i8(p, 26);
  m.hmsl_hp_e4m = le_i8(p, 27);
  m.h_acc_e4m = le_u32(p, 28);
  m.v_acc_e4m = le_u32(p, 32);
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

namespace {

void put_u8(std::vector<std::uint8_t>& out, unsigned v) { out.push_back(static_cast<std::uint8_t>(v)); }
void put_i8(std::vector<std::uint8_t>& out, std::int8_t v) { out.push_back(std::bit_cast<std::uint8_t>(v)); }
void put_i32(std::vector<std::uint8_t>& out, std::int32_t v) { framing::put_le_u32(out, std::bit_cast<std::uint32_t>(v)); }

}  // namespace

std::vector<std::uint8_t> encode_nav_pvt(const NavPvt& m) {
  std::vector<std::uint8_t> p;
  p.reserve(NavPvt::kBytes);
  framing::put_le_u32(p, m.itow_ms);
  framing::put_le_u16(p, m.year);
  for (const unsigned v : {unsigned{m.month}, unsigned{m.day}, unsigned{m.hour}, unsigned{m.minute}, unsigned{m.second}}) put_u8(p, v);
  put_u8(p, (m.valid_date ? 0x01U : 0U) | (m.valid_time ? 0x02U : 0U) | (m.fully_resolved ? 0x04U : 0U));
  framing::put_le_u32(p, m.time_accuracy_ns);
  put_i32(p, m.nano_ns);
  put_u8(p, m.fix_type_raw);
  put_u8(p, (m.gnss_fix_ok ? 0x01U : 0U) | (m.diff_soln ? 0x02U : 0U) | (m.head_veh_valid ? 0x20U : 0U) |
                (static_cast<unsigned>(m.carr_soln) << 6U));
  put_u8(p, 0);  // flags2
  put_u8(p, m.num_sv);
  for (const std::int32_t v : {m.lon_e7, m.lat_e7, m.height_mm, m.hmsl_mm}) put_i32(p, v);
  framing::put_le_u32(p, m.h_acc_mm);
  framing::put_le_u32(p, m.v_acc_mm);
  for (const std::int32_t v : {m.vel_n_mmps, m.vel_e_mmps, m.vel_d_mmps, m.ground_speed_mmps, m.head_mot_e5deg}) put_i32(p, v);
  framing::put_le_u32(p, m.speed_acc_mmps);
  framing::put_le_u32(p, m.head_acc_e5deg);
  framing::put_le_u16(p, m.pdop_e2);
  framing::put_le_u16(p, m.invalid_llh ? 0x01 : 0x00);  // flags3
  framing::put_le_u32(p, 0);                             // reserved
  put_i32(p, m.head_veh_e5deg);
  framing::put_le_u32(p, 0);                             // magDec, magAcc
  return encode_frame(kClassNav, kIdNavPvt, p);
}

std::vector<std::uint8_t> encode_nav_hpposllh(const NavHpposllh& m) {
  std::vector<std::uint8_t> p;
  p.reserve(NavHpposllh::kBytes);
  put_u8(p, m.version);
  put_u8(p, 0);
  put_u8(p, 0);
  put_u8(p, m.invalid_llh ? 0x01U : 0U);
  framing::put_le_u32(p, m.itow_ms);
  for (const std::int32_t v : {m.lon_e7, m.lat_e7, m.height_mm, m.hmsl_mm}) put_i32(p, v);
  for (const std::int8_t v : {m.lon_hp_e9, m.lat_hp_e9, m.height_hp_e4m, m.hmsl_hp_e4m}) put_i8(p, v);
  framing::put_le_u32(p, m.h_acc_e4m);
  framing::put_le_u32(p, m.v_acc_e4m);
  return encode_frame(kClassNav, kIdNavHpposllh, p);
}

}  // namespace trajroi::ublox
