#include "trajroi/roi/centres.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace trajroi::roi {
namespace {

using V = Eigen::Vector2d;
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(Centres, CountIsFloorOfLengthOverSpacingPlusOne) {
  const Trajectory t({V(0, 0), V(83, 0)});
  std::vector<Centre> c;
  place_centres(t, 0.0, kInf, 9.0, c);  // the paper's 150 % circle row
  ASSERT_EQ(c.size(), 10u);
  EXPECT_EQ(c.back().position, V(81, 0));
  place_centres(t, 0.0, kInf, 0.3, c);  // 10 % rectangle row: ⌊83 / 0.3⌋ + 1
  EXPECT_EQ(c.size(), 277u);
  place_centres(t, 0.0, kInf, 83.0, c);  // exactly the length: both ends
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[1].position, V(83, 0));
}

TEST(Centres, StartAndLookAheadAreClamped) {
  const Trajectory t({V(0, 0), V(10, 0), V(10, 10)});
  std::vector<Centre> c;
  place_centres(t, 8.0, 5.0, 2.0, c);  // s = 8, 10, 12
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].position, V(8, 0));
  EXPECT_EQ(c[1].position, V(10, 0));
  EXPECT_DOUBLE_EQ(c[1].theta_rad, std::numbers::pi / 2);
  EXPECT_EQ(c[2].position, V(10, 2));
  EXPECT_DOUBLE_EQ(c[2].s_m, 12.0);
  place_centres(t, 18.0, 100.0, 5.0, c);  // look-ahead past the end: stops at the end
  ASSERT_EQ(c.size(), 1u);
  place_centres(t, 50.0, 100.0, 5.0, c);  // start past the end: the end point
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].position, V(10, 10));
  place_centres(t, -3.0, 0.0, 5.0, c);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].position, V(0, 0));
}

TEST(Centres, TrajectoryShorterThanSpacingGivesOneCentre) {
  const Trajectory t({V(0, 0), V(1, 0)});
  std::vector<Centre> c;
  place_centres(t, 0.0, kInf, 6.0, c);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].position, V(0, 0));
}

TEST(Centres, RejectsBadSpacingAndLookAhead) {
  const Trajectory t({V(0, 0), V(10, 0)});
  std::vector<Centre> c;
  for (double d : {0.0, -1.0, std::nan(""), kInf}) {
    EXPECT_THROW(place_centres(t, 0.0, kInf, d, c), std::invalid_argument) << d;
  }
  EXPECT_THROW(place_centres(t, 0.0, -1.0, 1.0, c), std::invalid_argument);
  EXPECT_THROW(place_centres(t, 0.0, std::nan(""), 1.0, c), std::invalid_argument);
  EXPECT_THROW(place_centres(t, 0.0, kInf, 1e-9, c), std::invalid_argument);  // 1e10 centres
}

TEST(Centres, SpacingFromRatio) {
  EXPECT_DOUBLE_EQ(spacing_from_ratio(1.5, 6.0), 9.0);
  EXPECT_DOUBLE_EQ(spacing_from_ratio(0.25, 3.0), 0.75);
}

// The factory keyframe 2 set-up: s0 = 26.07, a 42 m look-ahead and 21 m spacing (75 % of a
// 28 m circle). 26.07 + 42 − 26.07 is 41.99999999999999 in double, which must still give the
// three centres s0, s0 + 21 and s0 + 42.
TEST(Centres, LookAheadOfWholeSpacingsKeepsItsLastCentre) {
  const Trajectory t({{0.0, 0.0}, {110.0, 0.0}});
  ASSERT_LT((26.07 + 42.0) - 26.07, 42.0);  // the rounding this test is about
  std::vector<Centre> out;
  place_centres(t, 26.07, 42.0, 21.0, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_DOUBLE_EQ(out.back().s_m, 26.07 + 42.0);
  place_centres(t, 26.07, 42.0, 3.0, out);
  EXPECT_EQ(out.size(), 15u);
  // Clipped by the end: no centre past it.
  place_centres(t, 100.0, 42.0, 5.0, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_DOUBLE_EQ(out.back().s_m, 110.0);
}

}  // namespace
}  // namespace trajroi::roi
