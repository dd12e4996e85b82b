#pragma once

// Attitude conventions.
//
// VN-100 (and most AHRS): yaw/pitch/roll are 3-2-1 Euler angles of the body frame FRD
// (x forward, y right, z down) relative to local NED (x north, y east, z down); yaw is
// clockwise from MAGNETIC north, pitch positive nose up, roll positive right side down.
//
// trajroi: robot and sensor frames are FLU (REP-103: x forward, y left, z up); the global
// frame is ENU (x east, y north, z up); yaw is counter-clockwise from east.
//
//   global_from_robot = ENU_from_NED · Rz(declination) · NED_from_FRD(ypr) · FRD_from_FLU
//                       · imu_from_robot
// where declination (positive east) turns magnetic north into true north, and
// imu_from_robot = robot_from_imu⁻¹ is the IMU's configured mounting in the robot frame
// (the IMU's FLU axes expressed in the robot frame). Level and facing true north gives
// yaw_enu = +90°; facing east gives 0°.
#include <Eigen/Geometry>

namespace trajroi::pose {

struct ImuMounting {
  // Rotation of the IMU's own FLU axes relative to the robot frame (identity: aligned).
  Eigen::Quaterniond robot_from_imu = Eigen::Quaterniond::Identity();
  double magnetic_declination_deg = 0;  // positive east
};

// VN-100 yaw/pitch/roll (degrees, NED/FRD, magnetic) → rotation global(ENU)_from_robot(FLU).
[[nodiscard]] Eigen::Quaterniond enu_from_vn_ypr(double yaw_deg, double pitch_deg, double roll_deg,
                                                 const ImuMounting& mounting = {});
// The VN-100's rotation NED_from_FRD for its yaw/pitch/roll: Rz(yaw) Ry(pitch) Rx(roll).
[[nodiscard]] Eigen::Quaterniond ned_from_frd_ypr(double yaw_deg, double pitch_deg, double roll_deg);
// enu_from_vn_ypr from the VN-100's rotation NED_from_FRD itself: its DCM output (row-major, as the
// frame carries it: the real VN-100 logs in ../shared/data hold YPR and DCM in every frame,
// and the DCM equals Rz(yaw) Ry(pitch) Rx(roll)), or its quaternion output (x, y, z, w; the
// same rotation).
[[nodiscard]] Eigen::Quaterniond enu_from_vn_rotation(const Eigen::Quaterniond& ned_from_frd,
                                                      const ImuMounting& mounting = {});

// Fallback headings when no IMU attitude is available (the yaw only; roll and pitch are then
// taken as zero by the caller):
//  - from the GNSS course over ground (NAV-PVT headMot), trusted only above a speed, and
//    only for a robot that drives forward;
//  - from a moving-base baseline (NAV-RELPOSNED relPosHeading), with the baseline's
//    direction in the robot frame configured (e.g. antennas mounted rear → front: 0).
// Both take true bearings and return the robot's yaw in the global frame through `to_yaw`
// (GlobalFrame::global_yaw_from_true_bearing bound to the fix position).
struct HeadingFallback {
  double min_speed_mps = 1.0;
  double max_heading_acc_deg = 5.0;
  double baseline_yaw_in_robot_rad = 0.0;
};
struct HeadingCandidate {
  bool valid = false;
  double yaw_rad = 0.0;
};
template <class ToYaw>
[[nodiscard]] HeadingCandidate yaw_from_course(double head_mot_deg, double ground_speed_mps, double head_acc_deg,
                                               const HeadingFallback& cfg, ToYaw&& to_yaw) {
  if (!(ground_speed_mps >= cfg.min_speed_mps) || !(head_acc_deg <= cfg.max_heading_acc_deg)) return {};
  return {true, to_yaw(head_mot_deg)};
}
template <class ToYaw>
[[nodiscard]] HeadingCandidate yaw_from_baseline(double rel_heading_deg, bool heading_valid, double heading_acc_deg,
                                                 const HeadingFallback& cfg, ToYaw&& to_yaw) {
  if (!heading_valid || !(heading_acc_deg <= cfg.max_heading_acc_deg)) return {};
  return {true, to_yaw(rel_heading_deg) - cfg.baseline_yaw_in_robot_rad};
}

// Yaw (rad, ENU, counter-clockwise from east) of a bearing clockwise from north (degrees).
[[nodiscard]] double enu_yaw_from_bearing_deg(double bearing_deg) noexcept;

// Roll, pitch, yaw (rad) of an ENU_from_FLU rotation, REP-103 fixed-axis convention
// (R = Rz(yaw) Ry(pitch) Rx(roll)); pitch positive nose DOWN as REP-103 implies.
struct RollPitchYaw {
  double roll_rad = 0, pitch_rad = 0, yaw_rad = 0;
};
[[nodiscard]] RollPitchYaw roll_pitch_yaw(const Eigen::Quaterniond& global_from_robot) noexcept;

}  // namespace trajroi::pose
