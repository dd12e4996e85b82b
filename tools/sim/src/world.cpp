#include "trajroi/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace trajroi::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEpsilon_m = 1e-9;

// The parameter interval [lo, hi] in which o + t d lies within [a, b] along one axis.
bool slab(double o, double d, double a, double b, double& lo, double& hi) noexcept {
  if (std::abs(d) < 1e-15) return o >= a && o <= b;  // parallel: inside or never
  double t0 = (a - o) / d;
  double t1 = (b - o) / d;
  if (t0 > t1) std::swap(t0, t1);
  lo = std::max(lo, t0);
  hi = std::min(hi, t1);
  return lo <= hi;
}

}  // namespace

World::World(const WorldSpec& spec, double cell_m) : ground_reflectivity_(spec.ground_reflectivity), cell_m_(cell_m) {
  struct Bounds {
    double x_min, y_min, x_max, y_max;
  };
  std::vector<Bounds> bounds;
  for (const Box& b : spec.boxes) {
    const double c = std::cos(b.yaw_rad), s = std::sin(b.yaw_rad);
    const double hx = b.size_m.x() / 2.0, hy = b.size_m.y() / 2.0;
    boxes_.push_back({b.centre_m.x(), b.centre_m.y(), c, s, hx, hy, b.height_m, b.reflectivity});
    const double ex = std::abs(c) * hx + std::abs(s) * hy;
    const double ey = std::abs(s) * hx + std::abs(c) * hy;
    bounds.push_back({b.centre_m.x() - ex, b.centre_m.y() - ey, b.centre_m.x() + ex, b.centre_m.y() + ey});
  }
  for (const Cylinder& c : spec.cylinders) {
    cylinders_.push_back({c.centre_m.x(), c.centre_m.y(), c.radius_m, c.height_m, c.reflectivity});
    bounds.push_back({c.centre_m.x() - c.radius_m, c.centre_m.y() - c.radius_m, c.centre_m.x() + c.radius_m,
                      c.centre_m.y() + c.radius_m});
  }
  if (bounds.empty()) {
    cell_start_.assign(1, 0);
    return;
  }
  Bounds all = bounds[0];
  for (const Bounds& b : bounds) {
    all = {std::min(all.x_min, b.x_min), std::min(all.y_min, b.y_min), std::max(all.x_max, b.x_max),
           std::max(all.y_max, b.y_max)};
  }
  x0_ = all.x_min - cell_m_;
  y0_ = all.y_min - cell_m_;
  nx_ = static_cast<int>(std::ceil((all.x_max - x0_) / cell_m_)) + 1;
  ny_ = static_cast<int>(std::ceil((all.y_max - y0_) / cell_m_)) + 1;
  std::vector<std::vector<std::uint32_t>> cells(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_));
  for (std::size_t k = 0; k < bounds.size(); ++k) {
    const Bounds& b = bounds[k];
    const int i0 = static_cast<int>(std::floor((b.x_min - x0_) / cell_m_));
    const int i1 = static_cast<int>(std::floor((b.x_max - x0_) / cell_m_));
    const int j0 = static_cast<int>(std::floor((b.y_min - y0_) / cell_m_));
    const int j1 = static_cast<int>(std::floor((b.y_max - y0_) / cell_m_));
    const auto item = k < boxes_.size() ? static_cast<std::uint32_t>(k)
                                        : (static_cast<std::uint32_t>(k - boxes_.size()) | kCylinderBit);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i)
        cells[static_cast<std::size_t>(j * nx_ + i)].push_back(item);
    }
  }
  cell_start_.reserve(cells.size() + 1);
  for (const auto& cell : cells) {
    cell_start_.push_back(static_cast<std::uint32_t>(items_.size()));
    items_.insert(items_.end(), cell.begin(), cell.end());
  }
  cell_start_.push_back(static_cast<std::uint32_t>(items_.size()));
}

double World::BoxShape::hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const noexcept {
  const double rx = o.x() - cx, ry = o.y() - cy;
  const double ox = cos_yaw * rx + sin_yaw * ry;
  const double oy = -sin_yaw * rx + cos_yaw * ry;
  const double dx = cos_yaw * d.x() + sin_yaw * d.y();
  const double dy = -sin_yaw * d.x() + cos_yaw * d.y();
  double lo = -kInf, hi = kInf;
  if (!slab(ox, dx, -half_x, half_x, lo, hi) || !slab(oy, dy, -half_y, half_y, lo, hi) ||
      !slab(o.z(), d.z(), 0.0, height, lo, hi)) {
    return kInf;
  }
  return lo > kEpsilon_m ? lo : kInf;
}

double World::CylinderShape::hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const noexcept {
  const double ox = o.x() - cx, oy = o.y() - cy;
  const double a = d.x() * d.x() + d.y() * d.y();
  const double b = ox * d.x() + oy * d.y();
  const double k = ox * ox + oy * oy - radius * radius;
  double lo = -kInf, hi = kInf;
  if (a < 1e-15) {
    if (k > 0.0) return kInf;
  } else {
    const double disc = b * b - a * k;
    if (disc < 0.0) return kInf;
    const double root = std::sqrt(disc);
    lo = (-b - root) / a;
    hi = (-b + root) / a;
  }
  if (!slab(o.z(), d.z(), 0.0, height, lo, hi)) return kInf;
  return lo > kEpsilon_m ? lo : kInf;
}

std::optional<Hit> World::cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_range_m) const noexcept {
  double t_end = max_range_m;
  bool ground = false;
  if (d.z() < 0.0 && o.z() > 0.0) {
    const double t_ground = -o.z() / d.z();
    if (t_ground <= t_end) {
      t_end = t_ground;
      ground = true;
    }
  }
  double best = kInf;
  std::uint8_t best_reflectivity = 0;

  if (nx_ > 0) {
    // Clip the ray's span [0, t_end] to the grid's rectangle.
    double t0 = 0.0, t1 = t_end;
    const double gx1 = x0_ + nx_ * cell_m_, gy1 = y0_ + ny_ * cell_m_;
    if (slab(o.x(), d.x(), x0_, gx1, t0, t1) && slab(o.y(), d.y(), y0_, gy1, t0, t1)) {
      const double px = o.x() + t0 * d.x(), py = o.y() + t0 * d.y();
      int i = std::clamp(static_cast<int>(std::floor((px - x0_) / cell_m_)), 0, nx_ - 1);
      int j = std::clamp(static_cast<int>(std::floor((py - y0_) / cell_m_)), 0, ny_ - 1);
      const int step_i = d.x() > 0.0 ? 1 : -1;
      const int step_j = d.y() > 0.0 ? 1 : -1;
      const double inv_dx = std::abs(d.x()) > 1e-15 ? 1.0 / std::abs(d.x()) : kInf;
      const double inv_dy = std::abs(d.y()) > 1e-15 ? 1.0 / std::abs(d.y()) : kInf;
      const double next_x = x0_ + (i + (step_i > 0 ? 1 : 0)) * cell_m_;
      const double next_y = y0_ + (j + (step_j > 0 ? 1 : 0)) * cell_m_;
      double t_max_x = std::abs(d.x()) > 1e-15 ? (next_x - o.x()) / d.x() : kInf;
      double t_max_y = std::abs(d.y()) > 1e-15 ? (next_y - o.y()) / d.y() : kInf;
      const double t_delta_x = cell_m_ * inv_dx;
      const double t_delta_y = cell_m_ * inv_dy;
      while (true) {
        const std::size_t cell = static_cast<std::size_t>(j * nx_ + i);
        for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
          const std::uint32_t item = items_[k];
          const bool cylinder = (item & kCylinderBit) != 0;
          const double t = cylinder ? cylinders_[item & ~kCylinderBit].hit(o, d) : boxes_[item].hit(o, d);
          if (t < best) {
            best = t;
            best_reflectivity = cylinder ? cylinders_[item & ~kCylinderBit].reflectivity : boxes_[item].reflectivity;
          }
        }
        const double cell_exit = std::min(t_max_x, t_max_y);
        if (best <= cell_exit || cell_exit > t1) break;
        if (t_max_x < t_max_y) {
          i += step_i;
          t_max_x += t_delta_x;
          if (i < 0 || i >= nx_) break;
        } else {
          j += step_j;
          t_max_y += t_delta_y;
          if (j < 0 || j >= ny_) break;
        }
      }
    }
  }
  if (best <= t_end) return Hit{best, best_reflectivity};
  if (ground) return Hit{t_end, ground_reflectivity_};
  return std::nullopt;
}

}  // namespace trajroi::sim
