#include "trajroi/pose_input/pose_input.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>

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

std::string_view to_string(HeadingSource source) noexcept {
  switch (source) {
    case HeadingSource::kNone:
      return "none";
    case HeadingSource::kImu:
      return "imu";
    case HeadingSource::kBaseline:
      return "moving-base baseline";
    case HeadingSource::kCourse:
      return "course over ground";
    case HeadingSource::kHeld:
      return "held (last GNSS heading)";
    case HeadingSource::kConfigured:
      return "configured initial heading";
    case HeadingSource::kLocalization:
      return "localization";
  }
  return "unknown";
}

PoseInput::PoseInput(pose::GlobalFrame frame, const PoseInputConfig& config, pose::PoseBuffer& buffer)
    : frame_(std::move(frame)), config_(config), buffer_(buffer) {}

void PoseInput::gnss_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
  ubx_.feed(bytes, [&](const ublox::Message& m) { on_ubx(m, receive_ns); });
  // Only while this port has given no UBX frame: a healthy port pays nothing for the check.
  if (ubx_.counters().frames == 0) {
    vn_on_gnss_.feed(bytes, [&](std::span<const std::uint8_t>) { ++counters_.vn100_frames_on_gnss; });
    gnss_sniffer_.feed(bytes);
  }
}

void PoseInput::imu_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
  if (vn_.counters().frames == 0) {
    ubx_on_imu_.feed(bytes, [&](const ublox::Message&) { ++counters_.ubx_frames_on_imu; });
    imu_sniffer_.feed(bytes);
  }
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
  if (m.msg_class != ublox::kClassNav) {
    ++counters_.ubx_other;
    return;
  }
  if (m.msg_id == ublox::kIdNavRelposned && config_.attitude == AttitudeFrom::kGnss) {
    const auto d = ublox::decode_nav_relposned(m.payload);
    if (!d.ok()) {
      ++counters_.malformed;
      return;
    }
    relpos_ = d.value;
    return;
  }
  if (m.msg_id == ublox::kIdNavHpposllh) {
    const auto d = ublox::decode_nav_hpposllh(m.payload);
    if (!d.ok()) {
      ++counters_.malformed;
      return;
    }
    hp_ = d.value;
    return;
  }
  if (m.msg_id != ublox::kIdNavPvt) {
    ++counters_.ubx_other;
    return;
  }
  const auto d = ublox::decode_nav_pvt(m.payload);
  if (!d.ok()) {
    ++counters_.malformed;
    return;
  }
  const ublox::NavPvt& pvt = d.value;
  newest_pvt_ = pvt;
  ++pvt_count_;
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
  if (pvt.utc_valid()) gnss_utc_ = GnssUtc{pvt.utc_ns(), fix.t_ns, pvt.time_accuracy_ns};
  if (buffer_.add_fix(fix)) {
    ++counters_.fixes;
  } else {
    ++counters_.refused;
  }
  if (config_.attitude == AttitudeFrom::kGnss) gnss_heading(pvt, fix.t_ns);
}

void PoseInput::gnss_heading(const ublox::NavPvt& pvt, std::int64_t t_ns) {
  if (!last_position_) return;
  const pose::Geodetic where = *last_position_;
  const auto to_yaw = [&](double bearing_deg) { return frame_.global_yaw_from_true_bearing(bearing_deg, where); };
  pose::HeadingCandidate heading;
  HeadingSource source = HeadingSource::kNone;
  if (relpos_ && relpos_->itow_ms == pvt.itow_ms) {
    heading = pose::yaw_from_baseline(relpos_->rel_pos_heading_e5deg * 1e-5, relpos_->heading_valid,
                                      relpos_->acc_heading_e5deg * 1e-5, config_.heading, to_yaw);
    source = HeadingSource::kBaseline;
  }
  if (!heading.valid) {
    heading =
        pose::yaw_from_course(pvt.head_mot_deg(), pvt.ground_speed_mps(), pvt.head_acc_deg(), config_.heading, to_yaw);
    source = HeadingSource::kCourse;
  }
  if (heading.valid) {
    heading_yaw_rad_ = heading.yaw_rad;
  } else if (heading_yaw_rad_) {
    source = heading_source_ == HeadingSource::kConfigured ? HeadingSource::kConfigured : HeadingSource::kHeld;
  } else if (config_.initial_heading_deg) {
    heading_yaw_rad_ = to_yaw(*config_.initial_heading_deg);
    source = HeadingSource::kConfigured;
  } else {
    return;
  }
  if (add_attitude(Eigen::Quaterniond(Eigen::AngleAxisd(*heading_yaw_rad_, Eigen::Vector3d::UnitZ())), t_ns)) {
    ++counters_.gnss_headings;
    heading_source_ = source;
  }
}

bool PoseInput::add_attitude(const Eigen::Quaterniond& global_from_robot, std::int64_t t_ns) {
  pose::AttitudeSample attitude;
  attitude.global_from_robot = global_from_robot;
  attitude.t_ns = t_ns;
  if (buffer_.add_attitude(attitude)) {
    ++counters_.attitudes;
    return true;
  }
  ++counters_.refused;
  return false;
}

void PoseInput::on_external_pose(const ExternalPose& p) {
  if (!p.valid || !p.position.allFinite() || !p.orientation.coeffs().allFinite() || p.orientation.norm() < 0.5) {
    ++counters_.external_invalid;
    return;
  }
  pose::GnssFix fix;
  fix.t_ns = p.t_ns;
  fix.quality.fix_type = 3;
  fix.quality.gnss_fix_ok = true;
  fix.quality.h_acc_m = 0.0;
  fix.quality.rtk_fixed = true;
  Eigen::Quaterniond orientation = p.orientation.normalized();
  if (p.lat_lon) {
    const pose::Geodetic where{p.position.x(), p.position.y(), p.position.z()};
    try {
      fix.antenna_global_m = frame_.to_global(where);
    } catch (const std::exception&) {
      ++counters_.external_invalid;
      return;
    }
    orientation = Eigen::Quaterniond(frame_.global_from_local_enu(where)) * orientation;
  } else {
    fix.antenna_global_m = p.position;
  }
  if (!buffer_.add_fix(fix)) {
    ++counters_.refused;
    return;
  }
  ++counters_.external_poses;
  if (add_attitude(orientation, p.t_ns)) heading_source_ = HeadingSource::kLocalization;
}

void PoseInput::on_vn100(const vn100::Sample& s, std::int64_t receive_ns) {
  if (config_.attitude != AttitudeFrom::kImu) return;
  // The rotation NED_from_FRD, from whichever attitude output the sensor is configured for.
  Eigen::Quaterniond ned_from_frd;
  if (s.has(vn100::Field::kYawPitchRoll)) {
    ned_from_frd = pose::ned_from_frd_ypr(static_cast<double>(s.ypr_deg[0]), static_cast<double>(s.ypr_deg[1]),
                                          static_cast<double>(s.ypr_deg[2]));
  } else if (s.has(vn100::Field::kQuaternion)) {
    const auto& q = s.quaternion_xyzw;
    ned_from_frd = Eigen::Quaterniond(static_cast<double>(q[3]), static_cast<double>(q[0]), static_cast<double>(q[1]),
                                      static_cast<double>(q[2]));
  } else if (s.has(vn100::Field::kDcm)) {
    Eigen::Matrix3d dcm;
    for (int i = 0; i < 9; ++i)
      dcm(i / 3, i % 3) = static_cast<double>(s.dcm[static_cast<std::size_t>(i)]);
    // Re-orthonormalised: float rounding leaves it a little off a rotation.
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(dcm, Eigen::ComputeFullU | Eigen::ComputeFullV);
    ned_from_frd = Eigen::Quaterniond(Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose()));
  } else {
    ++counters_.imu_without_attitude;
    return;
  }
  if (!ned_from_frd.coeffs().allFinite() || ned_from_frd.norm() < 0.5) {
    ++counters_.malformed;
    return;
  }
  const Eigen::Quaterniond local = pose::enu_from_vn_rotation(ned_from_frd, config_.imu);
  // The attitude is relative to local north at the robot; turn it into the global frame's
  // axes (UTM convergence, or the small tilt of LocalCartesian away from its origin).
  const pose::Geodetic where = last_position_.value_or(frame_.to_geodetic(Eigen::Vector3d::Zero()));
  std::int64_t t_ns = 0;
  if (s.has(vn100::Field::kTimeStartup)) {
    t_ns = imu_clock_.map(static_cast<std::int64_t>(s.time_startup_ns), receive_ns);
  } else if (s.has(vn100::Field::kTimeGps)) {
    t_ns = imu_clock_.map(static_cast<std::int64_t>(s.time_gps_ns), receive_ns);
  } else {
    t_ns = receive_ns;
    ++counters_.imu_receive_stamped;
  }
  if (add_attitude(Eigen::Quaterniond(frame_.global_from_local_enu(where)) * local, t_ns - config_.imu_delay_ns)) {
    heading_source_ = HeadingSource::kImu;
  }
}

}  // namespace trajroi::pose_input
