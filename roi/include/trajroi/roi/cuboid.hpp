#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "trajroi/roi/filter_stats.hpp"

namespace trajroi::roi {

// The paper's baseline [20]: one long box around the robot, oriented with it. In the robot
// frame (REP-103) a point is inside when
//   x_min ≤ x ≤ x_max,  y_min ≤ y ≤ y_max,  z_min ≤ z ≤ z_max  (all inclusive).
struct CuboidExtent {
  double x_min_m;
  double x_max_m;
  double y_min_m;
  double y_max_m;
  double z_min_m;
  double z_max_m;
};

// A box of the given length (along x), width (along y) centred on the robot, with z limits.
[[nodiscard]] CuboidExtent centred_cuboid(double length_m, double width_m, double z_min_m, double z_max_m);

class CuboidRoi {
 public:
  // Throws std::invalid_argument for a NaN or inverted extent.
  CuboidRoi(const Eigen::Isometry3d& global_from_robot, const CuboidExtent& extent);

  [[nodiscard]] bool contains(double gx, double gy, double gz) const noexcept {
    const double dx = gx - t_.x();
    const double dy = gy - t_.y();
    const double dz = gz - t_.z();
    // robot-frame coordinates: Rᵀ (p − t)
    const double rx = r_(0, 0) * dx + r_(1, 0) * dy + r_(2, 0) * dz;
    const double ry = r_(0, 1) * dx + r_(1, 1) * dy + r_(2, 1) * dz;
    const double rz = r_(0, 2) * dx + r_(1, 2) * dy + r_(2, 2) * dz;
    return rx >= e_.x_min_m && rx <= e_.x_max_m && ry >= e_.y_min_m && ry <= e_.y_max_m && rz >= e_.z_min_m &&
           rz <= e_.z_max_m;
  }
  [[nodiscard]] const CuboidExtent& extent() const noexcept { return e_; }
  [[nodiscard]] const Eigen::Isometry3d& global_from_robot() const noexcept { return pose_; }

 private:
  Eigen::Isometry3d pose_;
  Eigen::Matrix3d r_;
  Eigen::Vector3d t_;
  CuboidExtent e_;
};

// Keeps the points (global frame) inside the cuboid; NaN/infinite points are counted and
// never kept. `kept` is cleared and gets ascending indices.
template <typename Point>
FilterStats cuboid_filter(const CuboidRoi& cuboid, std::span<const Point> points, IndexVector& kept) {
  struct NoZLimit {
    [[nodiscard]] bool contains(double) const noexcept { return true; }
  };
  FilterStats stats;
  stats.input = points.size();
  kept.clear();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto x = static_cast<double>(points[i].x);
    const auto y = static_cast<double>(points[i].y);
    const auto z = static_cast<double>(points[i].z);
    const Precheck pre = precheck(NoZLimit{}, x, y, z);
    if (pre != Precheck::kPass) {
      count_rejection(stats, pre);
      continue;
    }
    if (cuboid.contains(x, y, z)) kept.push_back(static_cast<std::uint32_t>(i));
  }
  stats.kept = kept.size();
  return stats;
}

}  // namespace trajroi::roi
