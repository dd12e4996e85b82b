#pragma once

// Ray casting against the scenario's world: the ground plane z = 0 and primitives standing on
// it (yawed boxes, vertical cylinders). Every primitive is a vertical extrusion, so a uniform
// 2-D grid over x, y finds the candidates: a ray walks the cells it crosses (Amanatides–Woo)
// and stops at the first cell whose exit lies beyond the nearest hit found.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "trajroi/sim/scenario.hpp"

namespace trajroi::sim {

struct Hit {
  double range_m;  // along the (unit) direction from the origin
  std::uint8_t reflectivity;
};

class World {
 public:
  explicit World(const WorldSpec& spec, double cell_m = 1.0);

  // The nearest surface along origin + t · direction, 0 < t ≤ max_range_m; `direction` must be
  // a unit vector. Surfaces are hit from outside only: a ray starting inside a primitive sees
  // through it.
  [[nodiscard]] std::optional<Hit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                        double max_range_m) const noexcept;

 private:
  struct BoxShape {
    double cx, cy, cos_yaw, sin_yaw, half_x, half_y, height;
    std::uint8_t reflectivity;
    // Entry distance of a ray into the box, or +∞.
    [[nodiscard]] double hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const noexcept;
  };
  struct CylinderShape {
    double cx, cy, radius, height;
    std::uint8_t reflectivity;
    [[nodiscard]] double hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const noexcept;
  };

  std::uint8_t ground_reflectivity_;
  std::vector<BoxShape> boxes_;
  std::vector<CylinderShape> cylinders_;
  // Grid: cell (i, j) holds items_[cell_start_[c] … cell_start_[c + 1]), c = j · nx + i; an
  // item is a box index, or a cylinder index with kCylinderBit set.
  static constexpr std::uint32_t kCylinderBit = 0x8000'0000U;
  double x0_ = 0.0, y0_ = 0.0, cell_m_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> cell_start_;
  std::vector<std::uint32_t> items_;
};

}  // namespace trajroi::sim
