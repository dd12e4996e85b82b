#pragma once

// Decoding of one VN-100 binary frame (already framed and CRC-checked) into named values.
// VN-100 conventions (kept as they are here; the pose library converts them):
//   yaw/pitch/roll in degrees, 3-2-1 Euler angles of the body frame (x forward, y right,
//   z down) relative to the local NED frame, yaw clockwise from magnetic north;
//   quaternion as (x, y, z, w), the same rotation; angular rates in rad/s, accelerations in
//   m/s², magnetic field in gauss, temperature in °C, pressure in kPa; TimeStartup and
//   TimeGps in ns.
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace trajroi::vn100 {

// Decoded quantities; `present` says which the frame carried.
enum class Field : std::uint8_t {
  kTimeStartup,
  kTimeGps,
  kTimeSyncIn,
  kYawPitchRoll,
  kQuaternion,
  kAngularRate,  // compensated
  kAccel,        // compensated
  kMag,          // compensated
  kUncompMag,
  kUncompAccel,
  kUncompGyro,
  kTemperature,
  kPressure,
  kDcm,
  kMagNed,
  kAccelNed,
  kLinearAccelBody,
  kLinearAccelNed,
  kYprUncertainty,
  kVpeStatus,
  kImuStatus,
  kDeltaTheta,
  kDeltaVel,
  kSyncInCount,
  kCount,
};
[[nodiscard]] std::string_view to_string(Field field) noexcept;

struct Sample {
  std::uint32_t present = 0;  // bit per Field
  [[nodiscard]] bool has(Field f) const noexcept { return (present & (1U << static_cast<unsigned>(f))) != 0; }
  void set(Field f) noexcept { present |= 1U << static_cast<unsigned>(f); }

  std::uint64_t time_startup_ns = 0;
  std::uint64_t time_gps_ns = 0;  // since the GPS epoch (1980-01-06)
  std::uint64_t time_sync_in_ns = 0;
  std::array<float, 3> ypr_deg{};
  std::array<float, 4> quaternion_xyzw{};
  std::array<float, 3> angular_rate_rps{};
  std::array<float, 3> accel_mps2{};
  std::array<float, 3> mag_gauss{};
  std::array<float, 3> uncomp_mag_gauss{};
  std::array<float, 3> uncomp_accel_mps2{};
  std::array<float, 3> uncomp_gyro_rps{};
  float temperature_c = 0;
  float pressure_kpa = 0;
  std::array<float, 9> dcm{};  // row-major
  std::array<float, 3> mag_ned_gauss{};
  std::array<float, 3> accel_ned_mps2{};
  std::array<float, 3> linear_accel_body_mps2{};
  std::array<float, 3> linear_accel_ned_mps2{};
  std::array<float, 3> ypr_uncertainty_deg{};
  std::uint16_t vpe_status = 0;
  std::uint16_t imu_status = 0;
  float delta_time_s = 0;
  std::array<float, 3> delta_theta_deg{};
  std::array<float, 3> delta_vel_mps{};
  std::uint32_t sync_in_count = 0;
};

// Decodes a whole frame (sync through CRC) whose layout parse_layout() accepts; returns false
// (and leaves `out` partially filled) when it does not.
[[nodiscard]] bool decode(std::span<const std::uint8_t> frame, Sample& out) noexcept;

// The frame (sync through CRC) carrying `sample`'s values for the fields selected in
// `group_fields` (index = group − 1, as encode_frame). Fields the sample does not hold are
// written as stored (zero by default). Throws std::invalid_argument for a selection that
// cannot be sized. decode(encode(s, f)) gives back every selected value bit for bit.
[[nodiscard]] std::vector<std::uint8_t> encode(const Sample& sample, const std::array<std::uint16_t, 8>& group_fields);

}  // namespace trajroi::vn100
