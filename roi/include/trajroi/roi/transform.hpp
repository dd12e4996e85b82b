#pragma once

#include <Eigen/Geometry>
#include <span>

#include "trajroi/roi/point.hpp"

namespace trajroi::roi {

// Naming: `a_from_b` maps coordinates given in frame b into frame a, so
// global_from_sensor = global_from_robot * robot_from_sensor  (ᴳp = ᴳ_R T · ᴿ_S T · ˢp).

// A planar pose as a 3-D isometry: translation (x_m, y_m, z_m), rotation yaw_rad about +z
// (counter-clockwise from +x, REP-103).
[[nodiscard]] Eigen::Isometry3d pose_from_xy_yaw(double x_m, double y_m, double yaw_rad, double z_m = 0.0);

// A sensor's mounting, a_from_b = T(xyz) · Rz(yaw) · Ry(pitch) · Rx(roll) (angles in rad).
[[nodiscard]] Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, double roll_rad, double pitch_rad,
                                                  double yaw_rad);

// A pose given as a translation and a unit quaternion (w, x, y, z), rebuilt always the same
// way (Quaterniond::toRotationMatrix, no renormalisation), so two programs that exchange these
// seven numbers transform points bit-identically.
[[nodiscard]] Eigen::Isometry3d pose_from_position_quaternion(const Eigen::Vector3d& position_m,
                                                              const Eigen::Quaterniond& orientation);

// out[i] = target_from_source · in[i] for every point, computed in double and stored in the
// output's precision; intensity is copied. `in` and `out` must have the same size and may be
// the same array (in-place). Allocates nothing. On a CPU with AVX, PointXYZI clouds take a
// vector path doing the same double operations in the same order (bit-identical results).
void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZI> in,
                      std::span<PointXYZI> out);
void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZd> in,
                      std::span<PointXYZd> out);
// The scalar code alone, whatever the CPU: the reference the vector path is tested against.
void transform_points_scalar(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZI> in,
                             std::span<PointXYZI> out);

}  // namespace trajroi::roi
