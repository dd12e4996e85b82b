#include "trajroi/roi/shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace trajroi::roi {
namespace {

using V = Eigen::Vector2d;

TEST(Circle, BoundaryIsInclusive) {
  EXPECT_TRUE(circle_contains(0, 0, 3, 3, 0));
  EXPECT_TRUE(circle_contains(0, 0, 3, 0, -3));
  EXPECT_TRUE(circle_contains(10, 5, 5, 13, 9));  // 3-4-5
  EXPECT_FALSE(circle_contains(0, 0, 3, 3.0000001, 0));
  EXPECT_FALSE(circle_contains(0, 0, 3, std::nan(""), 0));
  EXPECT_FALSE(circle_contains(0, 0, 3, std::numeric_limits<double>::infinity(), 0));
}

TEST(Rect, VerticesFollowAlgorithmTwo) {
  // θ = 0, a = 3, b = 6 at the origin: u = (1.5, 0), v = (0, −3).
  const RectGeometry g = make_rect_geometry(0, 0, 0, 3, 6);
  EXPECT_DOUBLE_EQ(g.ax, -1.5);
  EXPECT_DOUBLE_EQ(g.ay, 3.0);
  EXPECT_DOUBLE_EQ(g.bx, -1.5);
  EXPECT_DOUBLE_EQ(g.by, -3.0);
  EXPECT_DOUBLE_EQ(g.abx, 0.0);
  EXPECT_DOUBLE_EQ(g.aby, -6.0);
  EXPECT_DOUBLE_EQ(g.bcx, 3.0);
  EXPECT_DOUBLE_EQ(g.bcy, 0.0);
  EXPECT_DOUBLE_EQ(g.ab2, 36.0);
  EXPECT_DOUBLE_EQ(g.bc2, 9.0);
  // inclusive on all four edges
  EXPECT_TRUE(rect_contains(g, 1.5, 3.0));
  EXPECT_TRUE(rect_contains(g, -1.5, -3.0));
  EXPECT_TRUE(rect_contains(g, 0.0, 0.0));
  EXPECT_FALSE(rect_contains(g, 1.6, 0.0));
  EXPECT_FALSE(rect_contains(g, 0.0, 3.1));
}

TEST(Rect, HeightRunsAlongTheTangentWidthAcross) {
  // θ = 90°: height a = 2 along +y, width b = 8 along x.
  const RectGeometry g = make_rect_geometry(5, 5, std::numbers::pi / 2, 2, 8);
  EXPECT_TRUE(rect_contains(g, 5 + 3.9, 5));
  EXPECT_TRUE(rect_contains(g, 5, 5 + 0.9));
  EXPECT_FALSE(rect_contains(g, 5, 5 + 1.1));
  EXPECT_FALSE(rect_contains(g, 5 + 4.1, 5));
  // θ = 45°: the corner direction of a square is at 0° or 90° from the axes
  const RectGeometry d = make_rect_geometry(0, 0, std::numbers::pi / 4, 2, 2);
  EXPECT_TRUE(rect_contains(d, 0.0, 1.4));  // along the diagonal: √2 reach
  EXPECT_FALSE(rect_contains(d, 0.0, 1.42));
  EXPECT_FALSE(rect_contains(d, std::nan(""), 0));
}

TEST(RoiSets, RejectBadSizes) {
  const std::vector<Centre> none;
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(CircularRoiSet(bad, none), std::invalid_argument) << bad;
    EXPECT_THROW(RectangularRoiSet(bad, 1.0, none), std::invalid_argument) << bad;
    EXPECT_THROW(RectangularRoiSet(1.0, bad, none), std::invalid_argument) << bad;
    const Trajectory t({V(0, 0), V(1, 0)});
    EXPECT_THROW(CorridorRoiSet(t, 0, 1, bad), std::invalid_argument) << bad;
  }
  EXPECT_THROW(CircularRoiSet(1.0, none, ZLimits{2.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(CircularRoiSet(1.0, none, ZLimits{std::nan(""), 1.0}), std::invalid_argument);
}

TEST(Corridor, CoversTheSubPolylineBetweenS0AndS1) {
  const Trajectory t({V(0, 0), V(10, 0), V(10, 10)});
  const CorridorRoiSet c(t, 5.0, 15.0, 2.0);
  auto inside = [&](double x, double y) {
    for (std::size_t j = 0; j < c.size(); ++j)
      if (c.contains(j, x, y)) return true;
    return false;
  };
  EXPECT_TRUE(inside(5, 1));     // start, on the edge
  EXPECT_TRUE(inside(4, 0));     // within w/2 of the start point (round cap)
  EXPECT_FALSE(inside(3.9, 0));  // before s0
  EXPECT_TRUE(inside(11, 5));
  EXPECT_TRUE(inside(10, 6));     // the end cap at (10, 5)
  EXPECT_FALSE(inside(10, 6.1));  // past s1
  EXPECT_FALSE(inside(7, 1.01));
  EXPECT_EQ(c.size(), 2u);  // (5,0)→(10,0)→(10,5)
}

TEST(CellRelation, IsConservative) {
  const std::vector<Centre> centres{{V(0, 0), 0.0, 0.0}};
  const CircularRoiSet circles(3.0, centres);
  EXPECT_EQ(circles.relation(0, Box{-1, -1, 1, 1}, 1e-9), CellRelation::kInside);
  EXPECT_EQ(circles.relation(0, Box{2, 2, 3, 3}, 1e-9), CellRelation::kBoundary);  // (2,2): 2.83
  EXPECT_EQ(circles.relation(0, Box{3, 3, 4, 4}, 1e-9), CellRelation::kOutside);   // (3,3): 4.24
  // a cell whose far corner is exactly at r is not "inside": rounding must be left to the test
  EXPECT_EQ(circles.relation(0, Box{0, 0, 3, 0}, 1e-9), CellRelation::kBoundary);
}

// The relation compares squared distances: a radius below the margin leaves r − tol negative,
// whose square would be positive and call a tiny cell at the centre inside. No cell is.
TEST(CellRelation, ARadiusBelowTheMarginHasNoInsideCell) {
  const std::vector<Centre> centres{{V(0, 0), 0.0, 0.0}};
  const CircularRoiSet tiny(1e-10, centres);
  EXPECT_EQ(tiny.relation(0, Box{0, 0, 1e-12, 1e-12}, 1e-9), CellRelation::kBoundary);
  EXPECT_EQ(tiny.relation(0, Box{1.0, 1.0, 2.0, 2.0}, 1e-9), CellRelation::kOutside);
}

}  // namespace
}  // namespace trajroi::roi
