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
  const Eigen::Matrix3d& r = target_from_source.linear();
  const Eigen::Vector3d& t = target_from_source.translation();
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto x = static_cast<double>(in[i].x);
    const auto y = static_cast<double>(in[i].y);
    const auto z = static_cast<double>(in[i].z);
    out[i].x = static_cast<Scalar>(r(0, 0) * x + r(0, 1) * y + r(0, 2) * z + t.x());
    out[i].y = static_cast<Scalar>(r(1, 0) * x + r(1, 1) * y + r(1, 2) * z + t.y());
    out[i].z = static_cast<Scalar>(r(2, 0) * x + r(2, 1) * y + r(2, 2) * z + t.z());
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
