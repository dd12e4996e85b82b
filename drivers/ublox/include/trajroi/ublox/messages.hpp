#pragma once

// Decoders for the UBX messages trajroi uses for pose (u-blox M8 / F9 interface
// descriptions). Each takes a payload and returns the message with its fields in the
// receiver's own integer units (named so) plus SI accessors, or the reason it could not.
// Payloads are read field by field, little-endian; never cast to a struct.
#include <array>
#include <chrono>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace trajroi::ublox {

inline constexpr std::uint8_t kClassNav = 0x01;
inline constexpr std::uint8_t kClassAck = 0x05;
inline constexpr std::uint8_t kClassCfg = 0x06;
inline constexpr std::uint8_t kIdNavStatus = 0x03;
inline constexpr std::uint8_t kIdNavPvt = 0x07;
inline constexpr std::uint8_t kIdNavHpposllh = 0x14;
inline constexpr std::uint8_t kIdNavCov = 0x36;
inline constexpr std::uint8_t kIdNavRelposned = 0x3C;
inline constexpr std::uint8_t kIdAckNak = 0x00;
inline constexpr std::uint8_t kIdAckAck = 0x01;

enum class PayloadError : std::uint8_t { kNone, kWrongLength, kUnsupportedVersion };
[[nodiscard]] std::string_view to_string(PayloadError error) noexcept;

template <class T>
struct Decoded {
  T value{};
  PayloadError error = PayloadError::kNone;
  [[nodiscard]] bool ok() const noexcept { return error == PayloadError::kNone; }
};

// NAV-PVT fixType.
enum class FixType : std::uint8_t {
  kNoFix = 0,
  kDeadReckoningOnly = 1,
  k2D = 2,
  k3D = 3,
  kGnssDeadReckoning = 4,
  kTimeOnly = 5,
};
// Carrier-phase range solution (NAV-PVT flags bits 6–7, NAV-RELPOSNED flags bits 3–4).
enum class CarrierSolution : std::uint8_t { kNone = 0, kFloat = 1, kFixed = 2 };
[[nodiscard]] std::string_view to_string(CarrierSolution solution) noexcept;  // none/float/fixed

// UBX-NAV-PVT (0x01 0x07): 92 bytes (M8 and later); the 84-byte form of protocol 14 (u-blox 7)
// is accepted without the vehicle heading.
struct NavPvt {
  static constexpr std::size_t kBytes = 92;
  static constexpr std::size_t kBytesProtocol14 = 84;

  std::uint32_t itow_ms = 0;  // GPS time of week of the epoch
  std::uint16_t year = 0;
  std::uint8_t month = 0, day = 0, hour = 0, minute = 0, second = 0;  // UTC, second may be 60
  bool valid_date = false;
  bool valid_time = false;
  bool fully_resolved = false;
  std::uint32_t time_accuracy_ns = 0;
  std::int32_t nano_ns = 0;  // signed fraction to add to the second, −1e9 … 1e9
  std::uint8_t fix_type_raw = 0;
  bool gnss_fix_ok = false;  // fix within the receiver's accuracy masks
  bool diff_soln = false;    // differential corrections applied
  CarrierSolution carr_soln = CarrierSolution::kNone;
  bool head_veh_valid = false;
  std::uint8_t num_sv = 0;
  std::int32_t lon_e7 = 0, lat_e7 = 0;      // 1e-7 degree
  std::int32_t height_mm = 0, hmsl_mm = 0;  // above the ellipsoid / mean sea level
  std::uint32_t h_acc_mm = 0, v_acc_mm = 0;
  std::int32_t vel_n_mmps = 0, vel_e_mmps = 0, vel_d_mmps = 0, ground_speed_mmps = 0;
  std::int32_t head_mot_e5deg = 0;  // heading of motion, clockwise from north
  std::uint32_t speed_acc_mmps = 0, head_acc_e5deg = 0;
  std::uint16_t pdop_e2 = 0;
  bool invalid_llh = false;   // flags3 bit 0 (newer firmware)
  bool has_head_veh = false;  // 92-byte form only
  std::int32_t head_veh_e5deg = 0;

  bool operator==(const NavPvt&) const = default;
  [[nodiscard]] FixType fix_type() const noexcept;
  // The receiver flags date and time valid AND they form a real date and time of day.
  [[nodiscard]] bool utc_valid() const noexcept;
  [[nodiscard]] std::chrono::year_month_day date() const noexcept;
  // UTC of the epoch in ns since 1970 (the second plus nano); meaningful when utc_valid().
  [[nodiscard]] std::int64_t utc_ns() const noexcept;
  [[nodiscard]] double lat_deg() const noexcept { return lat_e7 * 1e-7; }
  [[nodiscard]] double lon_deg() const noexcept { return lon_e7 * 1e-7; }
  [[nodiscard]] double height_m() const noexcept { return height_mm * 1e-3; }
  [[nodiscard]] double hmsl_m() const noexcept { return hmsl_mm * 1e-3; }
  [[nodiscard]] double h_acc_m() const noexcept { return h_acc_mm * 1e-3; }
  [[nodiscard]] double v_acc_m() const noexcept { return v_acc_mm * 1e-3; }
  [[nodiscard]] double ground_speed_mps() const noexcept { return ground_speed_mmps * 1e-3; }
  [[nodiscard]] double head_mot_deg() const noexcept { return head_mot_e5deg * 1e-5; }
  [[nodiscard]] double head_acc_deg() const noexcept { return head_acc_e5deg * 1e-5; }
};

// UBX-NAV-HPPOSLLH (0x01 0x14): 36 bytes. Position = standard part + high-precision part.
struct NavHpposllh {
  static constexpr std::size_t kBytes = 36;
  std::uint8_t version = 0;
  bool invalid_llh = false;
  std::uint32_t itow_ms = 0;
  std::int32_t lon_e7 = 0, lat_e7 = 0, height_mm = 0, hmsl_mm = 0;
  std::int8_t lon_hp_e9 = 0, lat_hp_e9 = 0;        // 1e-9 degree, −99 … 99
  std::int8_t height_hp_e4m = 0, hmsl_hp_e4m = 0;  // 0.1 mm, −9 … 9
  std::uint32_t h_acc_e4m = 0, v_acc_e4m = 0;      // 0.1 mm
  bool operator==(const NavHpposllh&) const = default;

  // Combined in integers first, so the only rounding is the final scaling.
  [[nodiscard]] double lat_deg() const noexcept {
    return static_cast<double>(std::int64_t{lat_e7} * 100 + lat_hp_e9) * 1e-9;
  }
  [[nodiscard]] double lon_deg() const noexcept {
    return static_cast<double>(std::int64_t{lon_e7} * 100 + lon_hp_e9) * 1e-9;
  }
  [[nodiscard]] double height_m() const noexcept {
    return static_cast<double>(std::int64_t{height_mm} * 10 + height_hp_e4m) * 1e-4;
  }
  [[nodiscard]] double hmsl_m() const noexcept {
    return static_cast<double>(std::int64_t{hmsl_mm} * 10 + hmsl_hp_e4m) * 1e-4;
  }
  [[nodiscard]] double h_acc_m() const noexcept { return h_acc_e4m * 1e-4; }
  [[nodiscard]] double v_acc_m() const noexcept { return v_acc_e4m * 1e-4; }
};

// UBX-NAV-RELPOSNED (0x01 0x3C): version 0 (40 bytes, M8P) or 1 (64 bytes, F9). The vector
// from the reference (base or moving-base antenna) to the rover, in NED.
struct NavRelposned {
  std::uint8_t version = 0;
  std::uint16_t ref_station_id = 0;
  std::uint32_t itow_ms = 0;
  std::int32_t rel_pos_n_cm = 0, rel_pos_e_cm = 0, rel_pos_d_cm = 0;
  std::int8_t rel_pos_hp_n_e4m = 0, rel_pos_hp_e_e4m = 0, rel_pos_hp_d_e4m = 0;
  std::int32_t rel_pos_length_cm = 0;      // version 1
  std::int8_t rel_pos_hp_length_e4m = 0;   // version 1
  std::int32_t rel_pos_heading_e5deg = 0;  // version 1: clockwise from north
  std::uint32_t acc_n_e4m = 0, acc_e_e4m = 0, acc_d_e4m = 0;
  std::uint32_t acc_length_e4m = 0, acc_heading_e5deg = 0;  // version 1
  bool gnss_fix_ok = false, diff_soln = false, rel_pos_valid = false;
  CarrierSolution carr_soln = CarrierSolution::kNone;
  bool is_moving = false, ref_pos_miss = false, ref_obs_miss = false;
  bool heading_valid = false;  // version 1 only (relPosHeadingValid)

  [[nodiscard]] double rel_pos_n_m() const noexcept {
    return static_cast<double>(std::int64_t{rel_pos_n_cm} * 100 + rel_pos_hp_n_e4m) * 1e-4;
  }
  [[nodiscard]] double rel_pos_e_m() const noexcept {
    return static_cast<double>(std::int64_t{rel_pos_e_cm} * 100 + rel_pos_hp_e_e4m) * 1e-4;
  }
  [[nodiscard]] double rel_pos_d_m() const noexcept {
    return static_cast<double>(std::int64_t{rel_pos_d_cm} * 100 + rel_pos_hp_d_e4m) * 1e-4;
  }
  [[nodiscard]] double heading_deg() const noexcept { return rel_pos_heading_e5deg * 1e-5; }
  [[nodiscard]] double heading_acc_deg() const noexcept { return acc_heading_e5deg * 1e-5; }
};

// UBX-NAV-COV (0x01 0x36): 64 bytes; NED covariances in m² and m²/s², upper triangle
// NN NE ND EE ED DD.
struct NavCov {
  static constexpr std::size_t kBytes = 64;
  std::uint32_t itow_ms = 0;
  std::uint8_t version = 0;
  bool pos_cov_valid = false, vel_cov_valid = false;
  std::array<float, 6> pos_cov_ned{};
  std::array<float, 6> vel_cov_ned{};
};

// UBX-NAV-STATUS (0x01 0x03): 16 bytes.
struct NavStatus {
  static constexpr std::size_t kBytes = 16;
  std::uint32_t itow_ms = 0;
  std::uint8_t gps_fix = 0;  // same codes as FixType
  bool gps_fix_ok = false, diff_soln = false, week_set = false, tow_set = false;
  CarrierSolution carr_soln = CarrierSolution::kNone;  // flags2 bits 6–7
  std::uint32_t ttff_ms = 0, msss_ms = 0;
};

// UBX-ACK-ACK / ACK-NAK (0x05 0x01 / 0x00): the class and id of the message answered.
struct Ack {
  static constexpr std::size_t kBytes = 2;
  bool acknowledged = false;
  std::uint8_t msg_class = 0, msg_id = 0;
};

[[nodiscard]] Decoded<NavPvt> decode_nav_pvt(std::span<const std::uint8_t> payload) noexcept;
[[nodiscard]] Decoded<NavHpposllh> decode_nav_hpposllh(std::span<const std::uint8_t> payload) noexcept;
[[nodiscard]] Decoded<NavRelposned> decode_nav_relposned(std::span<const std::uint8_t> payload) noexcept;
[[nodiscard]] Decoded<NavCov> decode_nav_cov(std::span<const std::uint8_t> payload) noexcept;
[[nodiscard]] Decoded<NavStatus> decode_nav_status(std::span<const std::uint8_t> payload) noexcept;
// `msg_id` is kIdAckAck or kIdAckNak.
[[nodiscard]] Decoded<Ack> decode_ack(std::uint8_t msg_id, std::span<const std::uint8_t> payload) noexcept;

// Encoders (for the simulator and tests): the whole frame, checksum included. The 92-byte
// NAV-PVT form is written (the vehicle heading as stored). decode(encode(m)) == m field by
// field.
[[nodiscard]] std::vector<std::uint8_t> encode_nav_pvt(const NavPvt& message);
[[nodiscard]] std::vector<std::uint8_t> encode_nav_hpposllh(const NavHpposllh& message);

}  // namespace trajroi::ublox
