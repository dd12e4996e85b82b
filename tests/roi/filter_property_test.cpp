// Property: the grid filter keeps exactly the points the paper's double loop keeps, on random
// trajectories of every kind, with many points placed within 20 µm of ROI edges, where a
// single rounding difference would show.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/reference_filter.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::roi {
namespace {

using V = Eigen::Vector2d;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kTrajectoriesPerShape = 52;
constexpr int kPointsPerTrajectory = 20'000;

enum class PathKind { kStraight, kCurved, kZigZag, kSelfCrossing };

Trajectory random_trajectory(PathKind kind, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const V origin(-50.0 + 100.0 * u(rng), -50.0 + 100.0 * u(rng));
  const double heading = 2.0 * std::numbers::pi * u(rng);
  std::vector<V> w;
  switch (kind) {
    case PathKind::kStraight: {
      const double length = 5.0 + 80.0 * u(rng);
      w = {origin, origin + length * V(std::cos(heading), std::sin(heading))};
      break;
    }
    case PathKind::kCurved: {
      const double radius = 5.0 + 60.0 * u(rng);
      const double sweep = (u(rng) < 0.5 ? 1.0 : -1.0) * (0.3 + 2.5 * u(rng));
      const int n = 20 + static_cast<int>(200 * u(rng));
      const V centre = origin + radius * V(-std::sin(heading), std::cos(heading));
      for (int k = 0; k <= n; ++k) {
        const double a = heading - std::numbers::pi / 2 + sweep * k / n;
        w.push_back(centre + radius * V(std::cos(a), std::sin(a)));
      }
      break;
    }
    case PathKind::kZigZag: {
      V p = origin;
      w.push_back(p);
      for (int k = 0; k < 8; ++k) {
        const double a = heading + (k % 2 == 0 ? 1.0 : -1.0) * (0.3 + 1.2 * u(rng));
        p += (3.0 + 10.0 * u(rng)) * V(std::cos(a), std::sin(a));
        w.push_back(p);
      }
      break;
    }
    case PathKind::kSelfCrossing: {  // a figure eight, traced one and a half times
      const double size = 8.0 + 20.0 * u(rng);
      for (int k = 0; k <= 150; ++k) {
        const double t = 3.0 * std::numbers::pi * k / 150;
        const V local(size * std::sin(t), size * std::sin(t) * std::cos(t));
        w.push_back(origin + V(std::cos(heading) * local.x() - std::sin(heading) * local.y(),
                               std::sin(heading) * local.x() + std::cos(heading) * local.y()));
      }
      break;
    }
  }
  return Trajectory(std::move(w));
}

// Points: a third uniform over the chain's surroundings, a third exactly on an edge of a
// random ROI as computed in double (a circle's rim, a rectangle's side or corner, a capsule's
// rim), and a third within 20 µm of such an edge.
template <typename Point>
std::vector<Point> random_points(const Trajectory& t, std::span<const Centre> centres, double reach,
                                 std::mt19937_64& rng, auto edge_point) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_real_distribution<double> jitter(-20e-6, 20e-6);
  double x_min = kInf, y_min = kInf, x_max = -kInf, y_max = -kInf;
  for (const V& w : t.waypoints()) {
    x_min = std::min(x_min, w.x());
    y_min = std::min(y_min, w.y());
    x_max = std::max(x_max, w.x());
    y_max = std::max(y_max, w.y());
  }
  std::vector<Point> points;
  points.reserve(kPointsPerTrajectory);
  for (int i = 0; i < kPointsPerTrajectory; ++i) {
    V p;
    if (i % 3 == 0) {
      p = V(x_min - reach + (x_max - x_min + 2 * reach) * u(rng), y_min - reach + (y_max - y_min + 2 * reach) * u(rng));
    } else {
      const Centre& c = centres[std::uniform_int_distribution<std::size_t>(0, centres.size() - 1)(rng)];
      p = edge_point(c, u(rng), u(rng));
      if (i % 3 == 2) p += V(jitter(rng), jitter(rng));  // else exactly on the edge
    }
    using S = decltype(Point{}.x);
    Point point{};
    point.x = static_cast<S>(p.x());
    point.y = static_cast<S>(p.y());
    if (i % 997 == 5) point.x = std::numeric_limits<S>::quiet_NaN();  // the rare bad return
    if (i % 1999 == 7) point.z = std::numeric_limits<S>::infinity();
    points.push_back(point);
  }
  return points;
}

struct Totals {
  std::size_t points = 0;
  std::size_t kept = 0;
  std::size_t trajectories = 0;
};

template <typename RoiSet, typename Point>
void expect_equal(const RoiSet& set, const std::vector<Point>& points, Totals& totals, const std::string& label) {
  IndexVector ref;
  IndexVector fast;
  reference_filter(set, std::span<const Point>(points), ref);
  GridFilter<RoiSet> grid;
  grid.build(set);
  // Float clouds have vector scans; each must agree with the reference on its own.
  for (const SimdPath path :
       {SimdPath::kAuto, SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
    grid.filter(std::span<const Point>(points), fast, path);
    ASSERT_EQ(ref.size(), fast.size()) << label << " path " << static_cast<int>(path);
    ASSERT_EQ(ref, fast) << label << " path " << static_cast<int>(path);
  }
  totals.points += points.size();
  totals.kept += ref.size();
  ++totals.trajectories;
}

PathKind kind_of(int i) {
  return static_cast<PathKind>(i % 4);
}

template <typename Point>
void run_property(const char* shape, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Totals totals;
  for (int k = 0; k < kTrajectoriesPerShape; ++k) {
    const Trajectory t = random_trajectory(kind_of(k), rng);
    std::vector<Centre> centres;
    const std::string label = std::string(shape) + " trajectory " + std::to_string(k) + " seed " + std::to_string(seed);
    if (std::string_view(shape) == "circular") {
      const double r = 0.5 + 5.0 * u(rng);
      place_centres(t, 0.0, kInf, (0.1 + 1.5 * u(rng)) * 2 * r, centres);
      const CircularRoiSet set(r, centres);
      const auto points = random_points<Point>(t, centres, 2 * r, rng, [&](const Centre& c, double a, double) {
        return V(c.position + r * V(std::cos(2 * std::numbers::pi * a), std::sin(2 * std::numbers::pi * a)));
      });
      expect_equal(set, points, totals, label);
    } else if (std::string_view(shape) == "rectangular") {
      const double a = 0.5 + 6.0 * u(rng);
      const double b = 0.5 + 10.0 * u(rng);
      place_centres(t, 0.0, kInf, (0.1 + 1.5 * u(rng)) * a, centres);
      const RectangularRoiSet set(a, b, centres);
      const auto points = random_points<Point>(t, centres, a + b, rng, [&](const Centre& c, double p, double q) {
        // a point on the rectangle's outline (sides and, for q < 0.1, exact corners)
        const V along(std::cos(c.theta_rad), std::sin(c.theta_rad));
        const V across(-along.y(), along.x());
        const double side = std::floor(p * 4.0);
        const double f = q < 0.1 ? 0.0 : q * 2.0 - 1.0;
        if (side == 0) return V(c.position + a / 2 * along + f * b / 2 * across);
        if (side == 1) return V(c.position - a / 2 * along + f * b / 2 * across);
        if (side == 2) return V(c.position + f * a / 2 * along + b / 2 * across);
        return V(c.position + f * a / 2 * along - b / 2 * across);
      });
      expect_equal(set, points, totals, label);
    } else {
      const double w = 0.5 + 8.0 * u(rng);
      const double s0 = t.length_m() * 0.3 * u(rng);
      place_centres(t, 0.0, kInf, 0.5, centres);
      const CorridorRoiSet set(t, s0, s0 + t.length_m() * (0.2 + 0.8 * u(rng)), w);
      const auto points = random_points<Point>(t, centres, w, rng, [&](const Centre& c, double p, double) {
        const V across(-std::sin(c.theta_rad), std::cos(c.theta_rad));
        return V(c.position + (p < 0.5 ? 1.0 : -1.0) * w / 2 * across);
      });
      expect_equal(set, points, totals, label);
    }
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GE(totals.trajectories, 50u);
  EXPECT_GE(totals.points, 1'000'000u);
  // Not a vacuous comparison: a good share of points is kept, a good share is not.
  EXPECT_GT(totals.kept, totals.points / 10);
  EXPECT_LT(totals.kept, totals.points * 9 / 10);
  std::printf("[ property ] %s: %zu points over %zu trajectories, %zu kept, fast == reference\n", shape, totals.points,
              totals.trajectories, totals.kept);
}

TEST(FastEqualsReference, CircularDoublePoints) {
  run_property<PointXYZd>("circular", 1);
}
TEST(FastEqualsReference, RectangularDoublePoints) {
  run_property<PointXYZd>("rectangular", 2);
}
TEST(FastEqualsReference, CorridorDoublePoints) {
  run_property<PointXYZd>("corridor", 3);
}
TEST(FastEqualsReference, CircularFloatPoints) {
  run_property<PointXYZI>("circular", 4);
}
TEST(FastEqualsReference, RectangularFloatPoints) {
  run_property<PointXYZI>("rectangular", 5);
}

}  // namespace
}  // namespace trajroi::roi
