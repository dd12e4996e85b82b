#include "trajroi/roi/trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace trajroi::roi {
namespace {

using V = Eigen::Vector2d;

TEST(Trajectory, RejectsFewerThanTwoDistinctPoints) {
  EXPECT_THROW(Trajectory({}), TrajectoryError);
  EXPECT_THROW(Trajectory({V(1, 2)}), TrajectoryError);
  try {
    Trajectory t({V(1, 2), V(1, 2), V(1, 2)});
    FAIL() << "zero-length trajectory accepted";
  } catch (const TrajectoryError& e) {
    EXPECT_EQ(e.code(), TrajectoryErrc::kTooFewPoints);
  }
}

TEST(Trajectory, RejectsNonFiniteWaypoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const V& bad : {V(nan, 0), V(0, inf), V(-inf, 1)}) {
    try {
      Trajectory t({V(0, 0), bad, V(5, 5)});
      FAIL() << "non-finite waypoint accepted";
    } catch (const TrajectoryError& e) {
      EXPECT_EQ(e.code(), TrajectoryErrc::kNonFinitePoint);
      EXPECT_NE(std::string(e.what()).find("waypoint 1"), std::string::npos) << e.what();
    }
  }
}

TEST(Trajectory, RemovesConsecutiveDuplicatesOnly) {
  const Trajectory t({V(0, 0), V(0, 0), V(3, 4), V(3, 4), V(3, 0), V(0, 0)});
  ASSERT_EQ(t.waypoints().size(), 4u);  // the closing (0,0) is not consecutive: kept
  EXPECT_DOUBLE_EQ(t.length_m(), 5.0 + 4.0 + 3.0);
  EXPECT_EQ(t.segment_count(), 3u);
}

TEST(Trajectory, PointAndHeadingAlongAnLShape) {
  const Trajectory t({V(0, 0), V(10, 0), V(10, 10)});
  EXPECT_EQ(t.point_at(0.0), V(0, 0));
  EXPECT_EQ(t.point_at(4.0), V(4, 0));
  EXPECT_EQ(t.point_at(10.0), V(10, 0));
  EXPECT_EQ(t.point_at(13.0), V(10, 3));
  EXPECT_EQ(t.point_at(20.0), V(10, 10));
  // clamped outside [0, L]
  EXPECT_EQ(t.point_at(-5.0), V(0, 0));
  EXPECT_EQ(t.point_at(99.0), V(10, 10));
  EXPECT_DOUBLE_EQ(t.heading_at(5.0), 0.0);
  // at a vertex the heading is the outgoing segment's; at the end, the last segment's
  EXPECT_DOUBLE_EQ(t.heading_at(10.0), std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(t.heading_at(20.0), std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(t.heading_at(-1.0), 0.0);
}

TEST(Trajectory, AxisAlignedPointsAreExact) {
  // The paper's straight trajectory: P(k·d) must be exactly (k·d, 0).
  const Trajectory t({V(0, 0), V(83, 0)});
  for (int k = 0; k <= 138; ++k) {
    const double s = k * 0.6000000000000001;
    EXPECT_EQ(t.point_at(s), V(s, 0.0));
    EXPECT_EQ(t.heading_at(s), 0.0);
  }
}

TEST(Trajectory, ProjectionFindsClosestPoint) {
  const Trajectory t({V(0, 0), V(10, 0), V(10, 10)});
  Projection p = t.project(V(4, 3));
  EXPECT_DOUBLE_EQ(p.s_m, 4.0);
  EXPECT_DOUBLE_EQ(p.distance_m, 3.0);
  p = t.project(V(12, 6));
  EXPECT_DOUBLE_EQ(p.s_m, 16.0);
  EXPECT_DOUBLE_EQ(p.distance_m, 2.0);
  p = t.project(V(-3, -4));  // before the start: clamps to s = 0
  EXPECT_DOUBLE_EQ(p.s_m, 0.0);
  EXPECT_DOUBLE_EQ(p.distance_m, 5.0);
}

TEST(Trajectory, HintKeepsProgressMonotonicOnAHairpin) {
  // Out along y = 0, back along y = 1: a robot at (2, 0.6) on the way back is closer to the
  // outgoing leg, but with the hint it must stay on the return leg.
  const Trajectory t({V(0, 0), V(10, 0), V(10, 1), V(0, 1)});
  const Projection global = t.project(V(2, 0.4));
  EXPECT_NEAR(global.s_m, 2.0, 1e-12);
  const Projection hinted = t.project(V(2, 0.4), 15.0, 10.0);
  EXPECT_NEAR(hinted.s_m, 19.0, 1e-12);
  EXPECT_NEAR(hinted.distance_m, 0.6, 1e-12);
  // never backwards: a position behind the hint projects to the hint itself
  const Projection behind = t.project(V(9, 1), 15.0, 10.0);
  EXPECT_DOUBLE_EQ(behind.s_m, 15.0);
}

TEST(Trajectory, HintOnASelfCrossingPath) {
  // A figure-eight-like crossing at (5, 5): the second pass must win with a later hint.
  const Trajectory t({V(0, 0), V(10, 10), V(10, 0), V(0, 10)});
  const double first_pass = t.project(V(5, 5)).s_m;
  EXPECT_NEAR(first_pass, std::sqrt(50.0), 1e-12);
  const double second = t.project(V(5, 5), 25.0, 20.0).s_m;
  EXPECT_NEAR(second, std::sqrt(200.0) + 10.0 + std::sqrt(50.0), 1e-9);
}

TEST(TrajectoryCsv, ParsesCommentsBlankLinesAndCrlf) {
  const Trajectory t = parse_trajectory_csv("# header\n0,0\r\n\n  10 , 0  # inline\n10,+10\n", "t.csv");
  ASSERT_EQ(t.waypoints().size(), 3u);
  EXPECT_EQ(t.waypoints()[2], V(10, 10));
}

TEST(TrajectoryCsv, ErrorsNameFileAndLine) {
  struct Case {
    const char* text;
    const char* expected;
  };
  for (const Case& c :
       {Case{"0,0\n1,1\nabc\n", "t.csv:3:"}, Case{"0,0\n1\n", "t.csv:2:"}, Case{"0,0\n1,2,3\n", "t.csv:2:"},
        Case{"0,0\n1,2x\n", "t.csv:2:"}, Case{"0,0\n,2\n", "t.csv:2:"}, Case{"0,0\nnan,1\n", "t.csv:2:"},
        Case{"0,0\n", "t.csv: trajectory needs at least two"}, Case{"", "t.csv: trajectory needs at least two"}}) {
    try {
      (void)parse_trajectory_csv(c.text, "t.csv");
      FAIL() << "accepted: " << c.text;
    } catch (const TrajectoryError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(c.expected, 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace trajroi::roi
