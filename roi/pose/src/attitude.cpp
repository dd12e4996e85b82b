#include "trajroi/pose/attitude.hpp"

#include <cmath>

namespace trajroi::pose {

namespace {

constexpr double kDegToRad = 0.017453292519943295;

Eigen::Quaterniond about(const Eigen::Vector3d& axis, double rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(rad, axis));
}

// ENU_from_NED swaps x and y and negates z: a rotation by π about (1, 1, 0)/√2.
const Eigen::Quaterniond& enu_from_ned() {
  static const Eigen::Quaterniond q(Eigen::AngleAxisd(M_PI, Eigen::Vector3d(1.0, 1.0, 0.0).normalized()));
  return q;
}
// FRD_from_FLU negates y and z: a rotation by π about x.
const Eigen::Quaterniond& frd_from_flu() {
  static const Eigen::Quaterniond q(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  return q;
}

}  // namespace

Eigen::Quaterniond ned_from_frd_ypr(double yaw_deg, double pitch_deg, double roll_deg) {
  // 3-2-1 intrinsic: yaw about down, then pitch about the new y (right), then roll about x.
  return about(Eigen::Vector3d::UnitZ(), yaw_deg * kDegToRad) * about(Eigen::Vector3d::UnitY(), pitch_deg * kDegToRad) *
         about(Eigen::Vector3d::UnitX(), roll_deg * kDegToRad);
}

Eigen::Quaterniond enu_from_vn_ypr(double yaw_deg, double pitch_deg, double roll_deg, const ImuMounting& mounting) {
  return enu_from_vn_rotation(ned_from_frd_ypr(yaw_deg, pitch_deg, roll_deg), mounting);
}

Eigen::Quaterniond enu_from_vn_rotation(const Eigen::Quaterniond& ned_from_frd, const ImuMounting& mounting) {
  // Declination turns the magnetic NED frame into the true one: a rotation about down.
  const Eigen::Quaterniond true_from_magnetic =
      about(Eigen::Vector3d::UnitZ(), mounting.magnetic_declination_deg * kDegToRad);
  const Eigen::Quaterniond enu_from_imu =
      enu_from_ned() * true_from_magnetic * ned_from_frd.normalized() * frd_from_flu();
  return (enu_from_imu * mounting.robot_from_imu.conjugate()).normalized();
}

double enu_yaw_from_bearing_deg(double bearing_deg) noexcept {
  return std::remainder((90.0 - bearing_deg) * kDegToRad, 2.0 * M_PI);
}

RollPitchYaw roll_pitch_yaw(const Eigen::Quaterniond& q) noexcept {
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  RollPitchYaw out;
  out.pitch_rad = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  out.roll_rad = std::atan2(r(2, 1), r(2, 2));
  out.yaw_rad = std::atan2(r(1, 0), r(0, 0));
  return out;
}

}  // namespace trajroi::pose
