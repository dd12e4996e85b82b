#include "trajroi/pose_input/pose_input.hpp"

#include <Eigen/Geometry>

namespace trajroi::pose_input {

std::int64_t ClockMap::map(std::int64_t sensor_ns, std::int64_t receive_ns) noexcept {
  const std::int64_t offset = receive_ns - sensor_ns;
  if (offset_ns_ &&
      (sensor_ns < last_sensor_ns_ || offset - *offset_ns_ > threshold_ns_ || *offset_ns_ - offset > threshold_ns_)) {
    offset_ns_.reset();
    ++resets_;
  }
  if (!offset_ns_ || offset < *offset_ns_) offset_ns_ = offset;
  last_sensor_ns_ = sensor_ns;
  return sensor_ns + *offset_ns_;
}

PoseInput::PoseInput(pose::GlobalFrame frame, const PoseInputConfig& config, pose::PoseBuffer& buffer)
    : frame_(std::move(frame)), config_(config), buffer_(buffer) {}

void PoseInput::gnss_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
  ubx_.feed(bytes, [&](const ublox::Message& m) { on_ubx(m, receive_ns); });
}

void PoseInput::imu_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
  vn_.feed(bytes, [&](std::span<const std::uint8_t> frame) {
    vn100::Sample sample;
    if (vn100::decode(frame, sample)) {
      on_vn100(sample, receive_ns);
    } else {
      ++counters_.malformed;
    }
  });
}

void PoseInput::on_ubx(const ublox::Message& m, std::int64_t receive_ns) {
  if (m.msg_class != ublox::kClassNav) return;
  if (m.msg_id == ublox::kIdNavHpposllh) {
    const auto d = ublox::decode_nav_hpposllh(m.payload);
    if (!d.ok()) {
      ++counters_.malformed;
      return;
    }
    hp_ = d.value;
    return;
  }
  if (m.msg_id != ublox::kIdNavPvt) return;
  const auto d = ublox::decode_nav_pvt(m.payload);
  if (!d.ok()) {
    ++counters_.malformed;
    return;
  }
  const ublox::NavPvt& pvt = d.value;
  const bool hp = hp_ && hp_->itow_ms == pvt.itow_ms && !hp_->invalid_llh;
  pose::GnssFix fix;
  fix.quality.fix_type = pvt.fix_type_raw;
  fix.quality.gnss_fix_ok = pvt.gnss_fix_ok;
  fix.quality.h_acc_m = hp ? hp_->h_acc_m() : pvt.h_acc_m();
  fix.quality.rtk_fixed = pvt.carr_soln == ublox::CarrierSolution::kFixed;
  fix.quality.rtk_float = pvt.carr_soln == ublox::CarrierSolution::kFloat;
  if (pvt.invalid_llh) {
    ++counters_.invalid_position;
    if (!last_position_) return;
    fix.antenna_global_m = *last_global_;
  } else {
    const pose::Geodetic position = hp ? pose::Geodetic{hp_->lat_deg(), hp_->lon_deg(), hp_->height_m()}
                                       : pose::Geodetic{pvt.lat_deg(), pvt.lon_deg(), pvt.height_m()};
    // A position off the ellipsoid's range (a corrupt frame whose checksum happened to
    // match), or one the global frame cannot express (far outside a fixed UTM zone), is
    // counted and dropped; the conversion's exception must not reach the processing thread.
    try {
      fix.antenna_global_m = frame_.to_global(position);
    } catch (const std::exception&) {
      ++counters_.invalid_position;
      return;
    }
    last_position_ = position;
    last_global_ = fix.antenna_global_m;
    if (hp) ++counters_.high_precision;
  }
  fix.t_ns = gnss_clock_.map(std::int64_t{pvt.itow_ms} * 1'000'000, receive_ns) - config_.gnss_delay_ns;
  if (buffer_.add_fix(fix)) {
    ++counters_.fixes;
  } else {
    ++counters_.refused;
  }
}

void PoseInput::on_vn100(const vn100::Sample& s, std::int64_t receive_ns) {
  if (!s.has(vn100::Field::kTimeStartup) || !s.has(vn100::Field::kYawPitchRoll)) {
    ++counters_.imu_without_attitude;
    return;
  }
  const Eigen::Quaterniond local =
      pose::enu_from_vn_ypr(static_cast<double>(s.ypr_deg[0]), static_cast<double>(s.ypr_deg[1]),
                            static_cast<double>(s.ypr_deg[2]), config_.imu);
  // The attitude is relative to local north at the robot; turn it into the global frame's
  // axes (UTM convergence, or the small tilt of LocalCartesian away from its origin).
  const pose::Geodetic where = last_position_.value_or(frame_.to_geodetic(Eigen::Vector3d::Zero()));
  pose::AttitudeSample attitude;
  attitude.global_from_robot = Eigen::Quaterniond(frame_.global_from_local_enu(where)) * local;
  attitude.t_ns = imu_clock_.map(static_cast<std::int64_t>(s.time_startup_ns), receive_ns) - config_.imu_delay_ns;
  if (buffer_.add_attitude(attitude)) {
    ++counters_.attitudes;
  } else {
    ++counters_.refused;
  }
}

}  // namespace trajroi::pose_input
