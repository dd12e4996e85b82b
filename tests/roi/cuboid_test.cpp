#include "trajroi/roi/cuboid.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <numbers>

#include "trajroi/roi/point.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::roi {
namespace {

TEST(Cuboid, OrientedWithTheRobot) {
  // Robot at (10, 0) facing +y; box 20 m long, 4 m wide, z in [−1, 3].
  const CuboidRoi box(pose_from_xy_yaw(10, 0, std::numbers::pi / 2), centred_cuboid(20, 4, -1, 3));
  EXPECT_TRUE(box.contains(10, 9.9, 0));  // 9.9 m ahead
  EXPECT_FALSE(box.contains(10, 10.1, 0));
  EXPECT_TRUE(box.contains(11.9, -9, 0));  // 1.9 m to the right, 9 m behind
  EXPECT_FALSE(box.contains(12.1, 0, 0));  // 2.1 m to the right
  EXPECT_FALSE(box.contains(10, 0, 3.1));
  EXPECT_TRUE(box.contains(10, 0, -1));
}

TEST(Cuboid, FilterCountsNonFinite) {
  const CuboidRoi box(Eigen::Isometry3d::Identity(), centred_cuboid(10, 2, -1, 1));
  const std::vector<PointXYZd> points{{0, 0, 0}, {std::nan(""), 0, 0}, {6, 0, 0}, {-4, 0.9, 0.9}};
  IndexVector kept;
  const FilterStats stats = cuboid_filter(box, std::span<const PointXYZd>(points), kept);
  EXPECT_EQ(kept, (IndexVector{0, 3}));
  EXPECT_EQ(stats.non_finite, 1u);
}

TEST(Cuboid, RejectsInvertedExtent) {
  EXPECT_THROW(CuboidRoi(Eigen::Isometry3d::Identity(), centred_cuboid(10, 2, 1, -1)), std::invalid_argument);
  EXPECT_THROW(CuboidRoi(Eigen::Isometry3d::Identity(), centred_cuboid(-10, 2, -1, 1)), std::invalid_argument);
}

}  // namespace
}  // namespace trajroi::roi
