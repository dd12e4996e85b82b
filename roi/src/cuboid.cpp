#include "trajroi/roi/cuboid.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace trajroi::roi {

CuboidExtent centred_cuboid(double length_m, double width_m, double z_min_m, double z_max_m) {
  return {-length_m / 2.0, length_m / 2.0, -width_m / 2.0, width_m / 2.0, z_min_m, z_max_m};
}

CuboidRoi::CuboidRoi(const Eigen::Isometry3d& global_from_robot, const CuboidExtent& extent)
    : pose_(global_from_robot), r_(global_from_robot.linear()), t_(global_from_robot.translation()), e_(extent) {
  auto check = [](double lo, double hi, const char* axis) {
    if (std::isnan(lo) || std::isnan(hi) || lo > hi) {
      throw std::invalid_argument(std::string("cuboid ") + axis + " extent must satisfy min <= max, got [" +
                                  std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
  };
  check(e_.x_min_m, e_.x_max_m, "x (length)");
  check(e_.y_min_m, e_.y_max_m, "y (width)");
  check(e_.z_min_m, e_.z_max_m, "z (height)");
  if (!r_.allFinite() || !t_.allFinite()) throw std::invalid_argument("cuboid pose is not finite");
}

}  // namespace trajroi::roi
