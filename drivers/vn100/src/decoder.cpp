#include "trajroi/vn100/decoder.hpp"

#include <bit>
#include <stdexcept>

#include "trajroi/framing/little_endian.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::vn100 {

std::string_view to_string(Field field) noexcept {
  switch (field) {
    case Field::kTimeStartup:
      return "TimeStartup";
    case Field::kTimeGps:
      return "TimeGps";
    case Field::kTimeSyncIn:
      return "TimeSyncIn";
    case Field::kYawPitchRoll:
      return "YawPitchRoll";
    case Field::kQuaternion:
      return "Quaternion";
    case Field::kAngularRate:
      return "AngularRate";
    case Field::kAccel:
      return "Accel";
    case Field::kMag:
      return "Mag";
    case Field::kUncompMag:
      return "UncompMag";
    case Field::kUncompAccel:
      return "UncompAccel";
    case Field::kUncompGyro:
      return "UncompGyro";
    case Field::kTemperature:
      return "Temp";
    case Field::kPressure:
      return "Pres";
    case Field::kDcm:
      return "DCM";
    case Field::kMagNed:
      return "MagNed";
    case Field::kAccelNed:
      return "AccelNed";
    case Field::kLinearAccelBody:
      return "LinearAccelBody";
    case Field::kLinearAccelNed:
      return "LinearAccelNed";
    case Field::kYprUncertainty:
      return "YprU";
    case Field::kVpeStatus:
      return "VpeStatus";
    case Field::kImuStatus:
      return "ImuStatus";
    case Field::kDeltaTheta:
      return "DeltaTheta";
    case Field::kDeltaVel:
      return "DeltaVel";
    case Field::kSyncInCount:
      return "SyncInCnt";
    case Field::kCount:
      break;
  }
  return "unknown";
}

namespace {

class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, Sample& out) : bytes_(bytes), out_(out) {}

  template <std::size_t N>
  void floats(Field field, std::array<float, N>& dst, std::size_t at) noexcept {
    for (std::size_t i = 0; i < N; ++i)
      dst[i] = framing::le_f32(bytes_, at + 4 * i);
    out_.set(field);
  }
  void scalar(Field field, float& dst, std::size_t at) noexcept {
    dst = framing::le_f32(bytes_, at);
    out_.set(field);
  }
  void u64(Field field, std::uint64_t& dst, std::size_t at) noexcept {
    dst = framing::le_u64(bytes_, at);
    out_.set(field);
  }
  void u16(Field field, std::uint16_t& dst, std::size_t at) noexcept {
    dst = framing::le_u16(bytes_, at);
    out_.set(field);
  }
  void u32(Field field, std::uint32_t& dst, std::size_t at) noexcept {
    dst = framing::le_u32(bytes_, at);
    out_.set(field);
  }
  void delta_theta(Sample& s, std::size_t at) noexcept {  // dtime then dtheta (16 bytes)
    s.delta_time_s = framing::le_f32(bytes_, at);
    floats(Field::kDeltaTheta, s.delta_theta_deg, at + 4);
  }

 private:
  std::span<const std::uint8_t> bytes_;
  Sample& out_;
};

// The mirror of Reader: writes a Sample's values at the same offsets.
class Writer {
 public:
  explicit Writer(std::span<std::uint8_t> bytes) : bytes_(bytes) {}

  template <std::size_t N>
  void floats(Field, const std::array<float, N>& src, std::size_t at) noexcept {
    for (std::size_t i = 0; i < N; ++i)
      put32(at + 4 * i, std::bit_cast<std::uint32_t>(src[i]));
  }
  void scalar(Field, const float& v, std::size_t at) noexcept { put32(at, std::bit_cast<std::uint32_t>(v)); }
  void u64(Field, const std::uint64_t& v, std::size_t at) noexcept {
    put32(at, static_cast<std::uint32_t>(v));
    put32(at + 4, static_cast<std::uint32_t>(v >> 32));
  }
  void u16(Field, const std::uint16_t& v, std::size_t at) noexcept {
    bytes_[at] = static_cast<std::uint8_t>(v);
    bytes_[at + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  void u32(Field, const std::uint32_t& v, std::size_t at) noexcept { put32(at, v); }
  void delta_theta(const Sample& s, std::size_t at) noexcept {
    scalar(Field::kDeltaTheta, s.delta_time_s, at);
    floats(Field::kDeltaTheta, s.delta_theta_deg, at + 4);
  }

 private:
  void put32(std::size_t at, std::uint32_t v) noexcept {
    for (std::size_t i = 0; i < 4; ++i)
      bytes_[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  std::span<std::uint8_t> bytes_;
};

// Fields the VN-100 sends in more than one group land in the same Sample member.
template <class Access, class S>
void common_field(Access& r, S& s, unsigned bit, std::size_t at) noexcept {
  switch (bit) {
    case 0:
      r.u64(Field::kTimeStartup, s.time_startup_ns, at);
      break;
    case 1:
      r.u64(Field::kTimeGps, s.time_gps_ns, at);
      break;
    case 2:
      r.u64(Field::kTimeSyncIn, s.time_sync_in_ns, at);
      break;
    case 3:
      r.floats(Field::kYawPitchRoll, s.ypr_deg, at);
      break;
    case 4:
      r.floats(Field::kQuaternion, s.quaternion_xyzw, at);
      break;
    case 5:
      r.floats(Field::kAngularRate, s.angular_rate_rps, at);
      break;
    case 8:
      r.floats(Field::kAccel, s.accel_mps2, at);
      break;
    case 9:  // Imu: uncompensated accel then gyro
      r.floats(Field::kUncompAccel, s.uncomp_accel_mps2, at);
      r.floats(Field::kUncompGyro, s.uncomp_gyro_rps, at + 12);
      break;
    case 10:  // MagPres: compensated mag, temperature, pressure
      r.floats(Field::kMag, s.mag_gauss, at);
      r.scalar(Field::kTemperature, s.temperature_c, at + 12);
      r.scalar(Field::kPressure, s.pressure_kpa, at + 16);
      break;
    case 11:  // DeltaTheta: dtime, dtheta, dvel
      r.delta_theta(s, at);
      r.floats(Field::kDeltaVel, s.delta_vel_mps, at + 16);
      break;
    case 13:
      r.u32(Field::kSyncInCount, s.sync_in_count, at);
      break;
    default:
      break;  // position, velocity, INS status: not VN-100 quantities
  }
}

template <class Access, class S>
void time_field(Access& r, S& s, unsigned bit, std::size_t at) noexcept {
  switch (bit) {
    case 0:
      r.u64(Field::kTimeStartup, s.time_startup_ns, at);
      break;
    case 1:
      r.u64(Field::kTimeGps, s.time_gps_ns, at);
      break;
    case 4:
      r.u64(Field::kTimeSyncIn, s.time_sync_in_ns, at);
      break;
    case 7:
      r.u32(Field::kSyncInCount, s.sync_in_count, at);
      break;
    default:
      break;
  }
}

template <class Access, class S>
void imu_field(Access& r, S& s, unsigned bit, std::size_t at) noexcept {
  switch (bit) {
    case 0:
      r.u16(Field::kImuStatus, s.imu_status, at);
      break;
    case 1:
      r.floats(Field::kUncompMag, s.uncomp_mag_gauss, at);
      break;
    case 2:
      r.floats(Field::kUncompAccel, s.uncomp_accel_mps2, at);
      break;
    case 3:
      r.floats(Field::kUncompGyro, s.uncomp_gyro_rps, at);
      break;
    case 4:
      r.scalar(Field::kTemperature, s.temperature_c, at);
      break;
    case 5:
      r.scalar(Field::kPressure, s.pressure_kpa, at);
      break;
    case 6:
      r.delta_theta(s, at);
      break;
    case 7:
      r.floats(Field::kDeltaVel, s.delta_vel_mps, at);
      break;
    case 8:
      r.floats(Field::kMag, s.mag_gauss, at);
      break;
    case 9:
      r.floats(Field::kAccel, s.accel_mps2, at);
      break;
    case 10:
      r.floats(Field::kAngularRate, s.angular_rate_rps, at);
      break;
    default:
      break;
  }
}

template <class Access, class S>
void attitude_field(Access& r, S& s, unsigned bit, std::size_t at) noexcept {
  switch (bit) {
    case 0:
      r.u16(Field::kVpeStatus, s.vpe_status, at);
      break;
    case 1:
      r.floats(Field::kYawPitchRoll, s.ypr_deg, at);
      break;
    case 2:
      r.floats(Field::kQuaternion, s.quaternion_xyzw, at);
      break;
    case 3:
      r.floats(Field::kDcm, s.dcm, at);
      break;
    case 4:
      r.floats(Field::kMagNed, s.mag_ned_gauss, at);
      break;
    case 5:
      r.floats(Field::kAccelNed, s.accel_ned_mps2, at);
      break;
    case 6:
      r.floats(Field::kLinearAccelBody, s.linear_accel_body_mps2, at);
      break;
    case 7:
      r.floats(Field::kLinearAccelNed, s.linear_accel_ned_mps2, at);
      break;
    case 8:
      r.floats(Field::kYprUncertainty, s.ypr_uncertainty_deg, at);
      break;
    default:
      break;
  }
}

}  // namespace

namespace {

// Visits every field the layout selects, in wire order, with its payload offset.
template <class Access, class S>
void walk(const Layout& layout, Access& access, S& sample) noexcept {
  std::size_t at = layout.header_bytes;
  for (unsigned g = 0; g < 8; ++g) {
    const std::uint16_t mask = layout.fields[g];
    for (unsigned bit = 0; bit < 16; ++bit) {
      if ((mask & (1U << bit)) == 0) continue;
      const auto group = static_cast<Group>(g);
      switch (group) {
        case Group::kCommon:
          common_field(access, sample, bit, at);
          break;
        case Group::kTime:
          time_field(access, sample, bit, at);
          break;
        case Group::kImu:
          imu_field(access, sample, bit, at);
          break;
        case Group::kAttitude:
          attitude_field(access, sample, bit, at);
          break;
        default:
          break;
      }
      at += field_size(group, bit);
    }
  }
}

}  // namespace

bool decode(std::span<const std::uint8_t> frame, Sample& out) noexcept {
  const std::optional<Layout> layout = parse_layout(frame);
  if (!layout || frame.size() != layout->frame_bytes()) return false;
  out = Sample{};
  Reader reader(frame, out);
  walk(*layout, reader, out);
  return true;
}

std::vector<std::uint8_t> encode(const Sample& sample, const std::array<std::uint16_t, 8>& group_fields) {
  // The layout of the requested selection (encode_frame validates it and adds the CRC).
  std::vector<std::uint8_t> header{kSync, 0};
  for (std::size_t g = 0; g < group_fields.size(); ++g) {
    if (group_fields[g] == 0) continue;
    header[1] = static_cast<std::uint8_t>(header[1] | (1U << g));
    framing::put_le_u16(header, group_fields[g]);
  }
  const std::optional<Layout> layout = parse_layout(header);
  if (!layout) throw std::invalid_argument("VN-100 encode: field selection cannot be sized");
  std::vector<std::uint8_t> frame(layout->header_bytes + layout->payload_bytes);
  Writer writer(frame);
  walk(*layout, writer, sample);
  return encode_frame(group_fields, std::span<const std::uint8_t>(frame).subspan(layout->header_bytes));
}

}  // namespace trajroi::vn100
