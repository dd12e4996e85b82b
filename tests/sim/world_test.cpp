// Ray casting against analytic answers, and the grid walk against a brute-force test of
// every primitive.
#include "trajroi/sim/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace trajroi::sim {
namespace {

Box box(double cx, double cy, double sx, double sy, double h, double yaw_deg = 0.0, std::uint8_t refl = 77) {
  Box b;
  b.centre_m = {cx, cy};
  b.size_m = {sx, sy};
  b.height_m = h;
  b.yaw_rad = yaw_deg * std::numbers::pi / 180.0;
  b.reflectivity = refl;
  return b;
}

Cylinder cylinder(double cx, double cy, double r, double h) {
  Cylinder c;
  c.centre_m = {cx, cy};
  c.radius_m = r;
  c.height_m = h;
  c.reflectivity = 33;
  return c;
}

Eigen::Vector3d dir(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * std::numbers::pi / 180.0, e = elevation_deg * std::numbers::pi / 180.0;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

TEST(World, WallAtKnownDistance) {
  WorldSpec spec;
  spec.boxes.push_back(box(10.1, 0.0, 0.2, 40.0, 5.0));
  const World world(spec);
  const auto hit = world.cast({0, 0, 1}, dir(0, 0), 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range_m, 10.0, 1e-12);
  EXPECT_EQ(hit->reflectivity, 77);
  // 30° to the side: 10 / cos 30°; 10° up: 10 / cos 10°.
  EXPECT_NEAR(world.cast({0, 0, 1}, dir(30, 0), 100.0)->range_m, 10.0 / std::cos(std::numbers::pi / 6), 1e-12);
  EXPECT_NEAR(world.cast({0, 0, 1}, dir(0, 10), 100.0)->range_m, 10.0 / std::cos(std::numbers::pi / 18), 1e-12);
  // Over the wall's top (5 m): the ray at 30° up from 1 m passes 1 + 10 tan 30° = 6.77 m.
  EXPECT_FALSE(world.cast({0, 0, 1}, dir(0, 30), 100.0));
  // Beyond the maximum range: nothing.
  EXPECT_FALSE(world.cast({0, 0, 1}, dir(0, 0), 9.5));
}

TEST(World, GroundPlane) {
  const World world(WorldSpec{});
  const auto hit = world.cast({3, 4, 2}, dir(45, -30), 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range_m, 4.0, 1e-12);  // 2 / sin 30°
  EXPECT_EQ(hit->reflectivity, 20);
  EXPECT_FALSE(world.cast({3, 4, 2}, dir(45, 0), 100.0));   // parallel
  EXPECT_FALSE(world.cast({3, 4, 2}, dir(45, 10), 100.0));  // upwards
}

TEST(World, CylinderSideAndTop) {
  WorldSpec spec;
  spec.cylinders.push_back(cylinder(5.0, 0.0, 1.0, 1.5));
  const World world(spec);
  EXPECT_NEAR(world.cast({0, 0, 0.5}, dir(0, 0), 100.0)->range_m, 4.0, 1e-12);
  // Offset by 0.6 across: enters at x = 5 − sqrt(1 − 0.36) = 4.2.
  EXPECT_NEAR(world.cast({0, 0.6, 0.5}, dir(0, 0), 100.0)->range_m, 4.2, 1e-12);
  // From above, straight down on its top.
  EXPECT_NEAR(world.cast({5.2, 0.1, 3.0}, {0, 0, -1}, 100.0)->range_m, 1.5, 1e-12);
  EXPECT_EQ(world.cast({0, 0, 0.5}, dir(0, 0), 100.0)->reflectivity, 33);
}

TEST(World, YawedBoxShowsItsCorner) {
  WorldSpec spec;
  spec.boxes.push_back(box(10.0, 0.0, 2.0, 2.0, 3.0, 45.0));  // a diamond: corner at x = 10 − √2
  const World world(spec);
  EXPECT_NEAR(world.cast({0, 0, 1}, dir(0, 0), 100.0)->range_m, 10.0 - std::sqrt(2.0), 1e-9);
}

TEST(World, RaysFromInsideSeeThrough) {
  WorldSpec spec;
  spec.boxes.push_back(box(0.0, 0.0, 2.0, 2.0, 3.0));
  spec.boxes.push_back(box(10.1, 0.0, 0.2, 40.0, 5.0));
  const World world(spec);
  EXPECT_NEAR(world.cast({0, 0, 1}, dir(0, 0), 100.0)->range_m, 10.0, 1e-12);
}

// An independent reference: every primitive tested, no grid.
double brute_force(const WorldSpec& spec, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_range) {
  double best = std::numeric_limits<double>::infinity();
  for (const Box& b : spec.boxes) {
    const double c = std::cos(b.yaw_rad), s = std::sin(b.yaw_rad);
    const Eigen::Vector3d lo(-b.size_m.x() / 2, -b.size_m.y() / 2, 0.0),
        hi(b.size_m.x() / 2, b.size_m.y() / 2, b.height_m);
    const Eigen::Vector3d ol(c * (o.x() - b.centre_m.x()) + s * (o.y() - b.centre_m.y()),
                             -s * (o.x() - b.centre_m.x()) + c * (o.y() - b.centre_m.y()), o.z());
    const Eigen::Vector3d dl(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
    double t0 = -1e300, t1 = 1e300;
    for (int k = 0; k < 3; ++k) {
      const double a = (lo[k] - ol[k]) / dl[k], bb = (hi[k] - ol[k]) / dl[k];
      t0 = std::max(t0, std::min(a, bb));
      t1 = std::min(t1, std::max(a, bb));
    }
    if (t0 <= t1 && t0 > 1e-9) best = std::min(best, t0);
  }
  for (const Cylinder& cy : spec.cylinders) {
    const double ox = o.x() - cy.centre_m.x(), oy = o.y() - cy.centre_m.y();
    const double a = d.x() * d.x() + d.y() * d.y(), b = ox * d.x() + oy * d.y(),
                 k = ox * ox + oy * oy - cy.radius_m * cy.radius_m;
    const double disc = b * b - a * k;
    if (disc < 0) continue;
    double t0 = (-b - std::sqrt(disc)) / a, t1 = (-b + std::sqrt(disc)) / a;
    const double z0 = -o.z() / d.z(), z1 = (cy.height_m - o.z()) / d.z();
    t0 = std::max(t0, std::min(z0, z1));
    t1 = std::min(t1, std::max(z0, z1));
    if (t0 <= t1 && t0 > 1e-9) best = std::min(best, t0);
  }
  if (d.z() < 0) best = std::min(best, -o.z() / d.z());
  return best <= max_range ? best : std::numeric_limits<double>::infinity();
}

TEST(World, GridWalkAgreesWithBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pos(-40, 40), size(0.2, 6), height(0.5, 8), yaw(0, 180), unit(-1, 1);
  WorldSpec spec;
  for (int i = 0; i < 60; ++i)
    spec.boxes.push_back(box(pos(rng), pos(rng), size(rng), size(rng), height(rng), yaw(rng)));
  for (int i = 0; i < 40; ++i)
    spec.cylinders.push_back(cylinder(pos(rng), pos(rng), size(rng) / 4, height(rng)));
  const World world(spec, 1.0);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d o(pos(rng) * 1.5, pos(rng) * 1.5, 0.3 + 2.0 * (unit(rng) + 1.0));
    Eigen::Vector3d d(unit(rng), unit(rng), 0.3 * unit(rng));
    d.normalize();
    const double expected = brute_force(spec, o, d, 120.0);
    const auto hit = world.cast(o, d, 120.0);
    if (std::isinf(expected)) {
      // A ray starting inside a primitive sees through it in both.
      EXPECT_FALSE(hit) << i;
    } else {
      ASSERT_TRUE(hit) << i;
      EXPECT_NEAR(hit->range_m, expected, 1e-9) << i;
      ++hits;
    }
  }
  EXPECT_GT(hits, 10000);
}

}  // namespace
}  // namespace trajroi::sim
