#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/reference_filter.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::roi {
namespace {

using V = Eigen::Vector2d;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The same checks for every ROI method (TEST_P over shapes).
enum class Kind { kCircular, kRectangular, kCorridor };

class FilterBehaviour : public ::testing::TestWithParam<Kind> {
 protected:
  Trajectory trajectory_{{V(0, 0), V(20, 0)}};

  // Runs both algorithms, checks they agree, returns the kept indices.
  template <typename Point>
  IndexVector run(std::span<const Point> points, ZLimits z, FilterStats* stats) {
    std::vector<Centre> centres;
    place_centres(trajectory_, 0.0, kInf, 1.0, centres);
    IndexVector ref;
    IndexVector fast;
    FilterStats ref_stats;
    FilterStats fast_stats;
    auto both = [&](const auto& set) {
      ref_stats = reference_filter(set, points, ref);
      GridFilter<std::decay_t<decltype(set)>> grid;
      grid.build(set);
      for (const SimdPath path : {SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
        IndexVector other;
        const FilterStats other_stats = grid.filter(points, other, path);
        EXPECT_EQ(other, ref) << "path " << static_cast<int>(path);
        EXPECT_EQ(other_stats.non_finite, ref_stats.non_finite) << "path " << static_cast<int>(path);
        EXPECT_EQ(other_stats.outside_z, ref_stats.outside_z) << "path " << static_cast<int>(path);
      }
      fast_stats = grid.filter(points, fast);
    };
    switch (GetParam()) {
      case Kind::kCircular:
        both(CircularRoiSet(2.0, centres, z));
        break;
      case Kind::kRectangular:
        both(RectangularRoiSet(2.0, 4.0, centres, z));
        break;
      case Kind::kCorridor:
        both(CorridorRoiSet(trajectory_, 0.0, kInf, 4.0, z));
        break;
    }
    EXPECT_EQ(ref, fast);
    EXPECT_EQ(ref_stats.kept, fast_stats.kept);
    EXPECT_EQ(ref_stats.non_finite, fast_stats.non_finite);
    EXPECT_EQ(ref_stats.outside_z, fast_stats.outside_z);
    *stats = fast_stats;
    return fast;
  }
};

TEST_P(FilterBehaviour, EmptyCloud) {
  FilterStats stats;
  const std::vector<PointXYZI> none;
  EXPECT_TRUE(run(std::span<const PointXYZI>(none), {}, &stats).empty());
  EXPECT_EQ(stats.input, 0u);
}

TEST_P(FilterBehaviour, NonFinitePointsAreNeverKeptAndAreCounted) {
  const float nanf = std::numeric_limits<float>::quiet_NaN();
  const float inff = std::numeric_limits<float>::infinity();
  const std::vector<PointXYZI> points{{5, 0, 0, 1},    {nanf, 0, 0, 1}, {5, nanf, 0, 1},
                                      {5, 0, nanf, 1}, {inff, 0, 0, 1}, {5, -inff, 0, 1},
                                      {5, 0, inff, 1}, {6, 0.5f, 0, 1}, {50, 0, 0, 1}};
  FilterStats stats;
  const auto kept = run(std::span<const PointXYZI>(points), {}, &stats);
  EXPECT_EQ(kept, (IndexVector{0, 7}));
  EXPECT_EQ(stats.non_finite, 6u);
  EXPECT_EQ(stats.input, 9u);
}

TEST_P(FilterBehaviour, ZLimitsAreInclusiveAndCounted) {
  const std::vector<PointXYZd> points{{5, 0, -1}, {5, 0, -1.0001}, {5, 0, 2}, {5, 0, 2.0001}, {5, 0, 0}};
  FilterStats stats;
  const auto kept = run(std::span<const PointXYZd>(points), ZLimits{-1.0, 2.0}, &stats);
  EXPECT_EQ(kept, (IndexVector{0, 2, 4}));
  EXPECT_EQ(stats.outside_z, 2u);
}

// The vector scans find a point's cell by rounding down and one unsigned comparison with the
// grid's size: a point a fraction of a cell left of or below the grid, one beyond the int
// range, and one on the far side must all be off the grid as cell_index() finds them. Whole
// blocks of such points (so that the vector scans, not their scalar tails, see them), and a
// NaN intensity, which is not a reason to reject a point.
TEST_P(FilterBehaviour, PointsJustOffTheGridOrFarAwayAgreeOnEveryPath) {
  std::vector<PointXYZI> points;
  for (int i = 0; i < 160; ++i) {
    const float step = 0.013f * static_cast<float>(i);
    points.push_back({-2.6f + step, 0.3f, 0.0f, 1.0f});   // across the left edge
    points.push_back({10.0f, -2.6f + step, 0.0f, 1.0f});  // across the bottom edge
    points.push_back({20.6f + step, -0.2f, 0.0f, 1.0f});  // across the right edge
    points.push_back({3.0f, 0.4f + step, 0.0f, 1.0f});    // across the top edge
  }
  for (const float far : {3e9f, -3e9f, 1e20f, -1e20f, std::numeric_limits<float>::max(),
                          -std::numeric_limits<float>::max(), std::numeric_limits<float>::denorm_min(), -0.0f}) {
    for (int k = 0; k < 8; ++k) {
      points.push_back({far, 0.1f * static_cast<float>(k), 0.0f, 1.0f});
      points.push_back({0.5f * static_cast<float>(k), far, 0.0f, 1.0f});
    }
  }
  for (int k = 0; k < 16; ++k)
    points.push_back({static_cast<float>(k), 0.5f, 0.0f, k == 5 ? std::numeric_limits<float>::quiet_NaN() : 1.0f});
  FilterStats stats;
  const auto kept = run(std::span<const PointXYZI>(points), {}, &stats);
  EXPECT_GT(kept.size(), 100u);                 // the chain keeps some of each sweep
  EXPECT_LT(kept.size(), points.size() - 200);  // and drops the far and off-grid ones
  EXPECT_EQ(stats.non_finite, 0u);
  EXPECT_EQ(kept.back(), points.size() - 1);  // the block with a NaN intensity is kept whole
}

TEST_P(FilterBehaviour, KeepsAlongTheChainOnly) {
  const std::vector<PointXYZd> points{{0, 0, 0}, {10, 1.5, 0}, {20, -1.5, 0}, {10, 2.5, 0}, {-3, 0, 0}, {24, 0, 0}};
  FilterStats stats;
  const auto kept = run(std::span<const PointXYZd>(points), {}, &stats);
  EXPECT_EQ(kept, (IndexVector{0, 1, 2}));
}

// The vector scans reuse the cells of the previous firing's lanes where they have not
// changed, which is most of them in a LiDAR cloud. A VLP-16-like sweep from (10, 0): 16
// rings from 1 m to 11.5 m, 0.18° apart in azimuth, so each ring stays in a cell for a few
// firings and then crosses into the next, through boundary cells; every 97th firing has a
// non-finite return, which sends its block to the scalar code.
TEST_P(FilterBehaviour, AnOrganisedCloudGivesTheReferenceAnswer) {
  std::vector<PointXYZI> points;
  for (int firing = 0; firing < 2000; ++firing) {
    const double azimuth = firing * 0.18 * 3.14159265358979 / 180.0;
    for (int ring = 0; ring < 16; ++ring) {
      const double range = 1.0 + 0.7 * ring;
      PointXYZI& p = points.emplace_back();
      p.x = static_cast<float>(10.0 + range * std::cos(azimuth));
      p.y = static_cast<float>(range * std::sin(azimuth));
      p.z = 0.0f;
      p.intensity = static_cast<float>(ring);
      if (firing % 97 == 5 && ring == 3) p.y = std::numeric_limits<float>::quiet_NaN();
    }
  }
  FilterStats stats;
  const auto kept = run(std::span<const PointXYZI>(points), {}, &stats);
  EXPECT_EQ(stats.non_finite, 21u);
  // Rings within 2 m of the path are inside all the way round, the others for part of it.
  EXPECT_GT(kept.size(), points.size() / 8);
  EXPECT_LT(kept.size(), points.size() / 2);
}

INSTANTIATE_TEST_SUITE_P(AllShapes, FilterBehaviour,
                         ::testing::Values(Kind::kCircular, Kind::kRectangular, Kind::kCorridor),
                         [](const ::testing::TestParamInfo<Kind>& param_info) {
                           switch (param_info.param) {
                             case Kind::kCircular:
                               return std::string("circular");
                             case Kind::kRectangular:
                               return std::string("rectangular");
                             case Kind::kCorridor:
                               return std::string("corridor");
                           }
                           return std::string("unknown");
                         });

TEST(GridFilter, VectorScansApplyZLimitsLikeTheDoubleTest) {
  // Limits that are not floats, and whose nearest floats lie outside them (−1.30000002 rounds
  // down, 0.70000002 up): each path must admit exactly the float z values the double
  // comparison admits, including the floats just either side of each limit.
  const Trajectory t({V(0, 0), V(20, 0)});
  std::vector<Centre> centres;
  place_centres(t, 0.0, kInf, 1.0, centres);
  const ZLimits z{-1.30000002, 0.70000002};
  const CircularRoiSet set(2.0, centres, z);
  std::vector<PointXYZI> points;
  const float edges[] = {static_cast<float>(z.min_m), static_cast<float>(z.max_m)};
  for (int i = 0; i < 64; ++i) {
    const float edge = edges[i % 2];
    const float towards = (i / 2) % 2 == 0 ? -kInf : kInf;
    float value = edge;
    for (int k = 0; k < (i / 4) % 3; ++k)
      value = std::nextafter(value, towards);
    points.push_back({static_cast<float>(i % 20), 0.5f, value, 1.0f});
  }
  IndexVector ref;
  const FilterStats ref_stats = reference_filter(set, std::span<const PointXYZI>(points), ref);
  ASSERT_GT(ref.size(), 0u);
  ASSERT_GT(ref_stats.outside_z, 0u);
  GridFilter<CircularRoiSet> grid;
  grid.build(set);
  for (const SimdPath path : {SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
    IndexVector fast;
    const FilterStats stats = grid.filter(std::span<const PointXYZI>(points), fast, path);
    EXPECT_EQ(fast, ref) << "path " << static_cast<int>(path);
    EXPECT_EQ(stats.outside_z, ref_stats.outside_z) << "path " << static_cast<int>(path);
  }
}

TEST(GridFilter, EmptyChainKeepsNothing) {
  const CircularRoiSet set(1.0, std::vector<Centre>{});
  GridFilter<CircularRoiSet> grid;
  grid.build(set);
  const std::vector<PointXYZd> points{{0, 0, 0}};
  IndexVector kept{7};
  const FilterStats stats = grid.filter(std::span<const PointXYZd>(points), kept);
  EXPECT_TRUE(kept.empty());
  EXPECT_EQ(stats.kept, 0u);
}

TEST(GridFilter, HugeAreaStaysWithinTheCellCeiling) {
  // 10 km diagonal chain of 1 m circles: the grid coarsens instead of growing without bound.
  const Trajectory t({V(0, 0), V(7071, 7071)});
  std::vector<Centre> centres;
  place_centres(t, 0.0, kInf, 1.0, centres);
  const CircularRoiSet set(1.0, centres);
  GridFilter<CircularRoiSet> grid;
  grid.build(set);
  EXPECT_LE(grid.cell_count(), GridFilter<CircularRoiSet>::kMaxCells);
  const std::vector<PointXYZd> points{{5000, 5000, 0}, {5000, 5001.5, 0}, {5000.5, 5000.5, 0}};
  IndexVector fast;
  IndexVector ref;
  grid.filter(std::span<const PointXYZd>(points), fast);
  reference_filter(set, std::span<const PointXYZd>(points), ref);
  EXPECT_EQ(fast, ref);
  EXPECT_EQ(fast, (IndexVector{0, 2}));
}

}  // namespace
}  // namespace trajroi::roi
