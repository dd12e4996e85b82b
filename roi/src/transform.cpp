#include "trajroi/roi/transform.hpp"

#include <cassert>

namespace trajroi::roi {

Eigen::Isometry3d pose_from_xy_yaw(double x_m, double y_m, double yaw_rad, double z_m) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x_m, y_m, z_m);
  return pose;
}

Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, double roll_rad, double pitch_rad, double yaw_rad) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = xyz_m;
  t.linear() =
      (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  return t;
}

Eigen::Isometry3d pose_from_position_quaternion(const Eigen::Vector3d& position_m,
                                                const Eigen::Quaterniond& orientation) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = orientation.toRotationMatrix();
  t.translation() = position_m;
  return t;
}

namespace {

template <typename Point>
void transform_impl(const Eigen::Isometry3d& target_from_source, std::span<const Point> in, std::span<Point> out) {
  assert(in.size() == out.size());
  using Scalar = decltype(Point{}.x);
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto [x, y, z] = transform_point<Scalar>(target_from_source, in[i].x, in[i].y, in[i].z);
    out[i].x = x;
    out[i].y = y;
    out[i].z = z;
    if constexpr (requires { in[i].intensity; }) out[i].intensity = in[i].intensity;
  }
}

}  // namespace

void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZI> in,
                      std::span<PointXYZI> out) {
  transform_impl(target_from_source, in, out);
}

void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZd> in,
                      std::span<PointXYZd> out) {
  transform_impl(target_from_source, in, out);
}

}  // namespace trajroi::roi
