#include "trajroi/roi/transform.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

namespace trajroi::roi {
namespace {

TEST(Transform, ComposesGlobalFromRobotAndRobotFromSensor) {
  // Robot at (10, 5) facing +y; sensor 1 m ahead of the robot's origin, 2 m up.
  const Eigen::Isometry3d global_from_robot = pose_from_xy_yaw(10, 5, std::numbers::pi / 2);
  const Eigen::Isometry3d robot_from_sensor = pose_from_xy_yaw(1, 0, 0, 2);
  const Eigen::Isometry3d global_from_sensor = global_from_robot * robot_from_sensor;
  std::vector<PointXYZI> in{{1, 0, 0, 7}, {0, 1, -2, 8}};
  std::vector<PointXYZI> out(2);
  transform_points(global_from_sensor, in, out);
  // 1 m ahead of the sensor: sensor at (10, 6, 2), ahead = +y → (10, 7, 2)
  EXPECT_NEAR(out[0].x, 10.0f, 1e-5f);
  EXPECT_NEAR(out[0].y, 7.0f, 1e-5f);
  EXPECT_NEAR(out[0].z, 2.0f, 1e-5f);
  EXPECT_EQ(out[0].intensity, 7.0f);
  // 1 m to the sensor's left (+y) = −x in the global frame, 2 m down → ground
  EXPECT_NEAR(out[1].x, 9.0f, 1e-5f);
  EXPECT_NEAR(out[1].y, 6.0f, 1e-5f);
  EXPECT_NEAR(out[1].z, 0.0f, 1e-5f);
  EXPECT_EQ(out[1].intensity, 8.0f);
}

// Whatever path the CPU takes (AVX here when it has it), every coordinate is the scalar
// code's to the bit: LiDAR-range and far-from-origin points, tilted poses, odd counts.
TEST(Transform, EveryPathGivesTheScalarBits) {
  std::mt19937 rng(20);
  std::uniform_real_distribution<float> coordinate(-120.0f, 120.0f);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{384}, std::size_t{1001}}) {
    Eigen::Isometry3d pose =
        pose_from_xyz_rpy(Eigen::Vector3d(4321.123, -987.654, 12.5), 0.1 * angle(rng), 0.1 * angle(rng), angle(rng));
    std::vector<PointXYZI> in(n);
    for (PointXYZI& p : in)
      p = {coordinate(rng), coordinate(rng), 0.1f * coordinate(rng), static_cast<float>(rng() % 256)};
    std::vector<PointXYZI> fast(n), scalar(n);
    transform_points(pose, in, fast);
    transform_points_scalar(pose, in, scalar);
    // (memcmp on no points would be handed the empty vectors' null data.)
    ASSERT_TRUE(n == 0 || std::memcmp(fast.data(), scalar.data(), n * sizeof(PointXYZI)) == 0) << n << " points";
  }
}

// A decoder's record: x, y, z first, other fields, an 8-bit intensity further on (the layout
// of vlp16::Point, 28 bytes).
struct Record {
  float x, y, z;
  float distance_m, azimuth_deg;
  std::uint32_t time_offset_ns;
  std::uint8_t intensity, laser, ring, return_type;
};

// Placing records straight from the decoder's array gives the bits of copying them into
// PointXYZI and transforming those with the scalar code: every count (the fours and the rest),
// a far-from-origin tilted pose, and every intensity from 0 to 255.
TEST(Transform, RecordsGiveTheBitsOfTheCopiedPoints) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> coordinate(-120.0f, 120.0f);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  for (const std::size_t n : {std::size_t{1}, std::size_t{3}, std::size_t{4}, std::size_t{5}, std::size_t{1023}}) {
    const Eigen::Isometry3d pose =
        pose_from_xyz_rpy(Eigen::Vector3d(-5321.5, 4987.25, 3.5), 0.1 * angle(rng), 0.1 * angle(rng), angle(rng));
    std::vector<Record> records(n);
    std::vector<PointXYZI> copied(n);
    for (std::size_t i = 0; i < n; ++i) {
      records[i] = {coordinate(rng), coordinate(rng), 0.1f * coordinate(rng), 1.0f, 2.0f, 3, 0, 4, 5, 6};
      records[i].intensity = static_cast<std::uint8_t>(i % 256);
      copied[i] = {records[i].x, records[i].y, records[i].z, static_cast<float>(records[i].intensity)};
    }
    std::vector<PointXYZI> placed(n), scalar(n);
    transform_records(pose, std::span<const Record>(records), placed.data());
    transform_points_scalar(pose, copied, scalar);
    ASSERT_EQ(std::memcmp(placed.data(), scalar.data(), n * sizeof(PointXYZI)), 0) << n << " records";
    EXPECT_EQ(placed[n - 1].intensity, static_cast<float>((n - 1) % 256));
  }
}

TEST(Transform, InPlaceEqualsOutOfPlace) {
  const Eigen::Isometry3d pose = pose_from_xy_yaw(-3.5, 2.25, 0.7, 0.4);
  std::vector<PointXYZd> a{{1.5, -2.0, 0.25}, {100.0, 3.0, -1.0}};
  std::vector<PointXYZd> b(a.size());
  transform_points(pose, a, b);
  transform_points(pose, a, a);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].y, b[i].y);
    EXPECT_EQ(a[i].z, b[i].z);
  }
  // and against Eigen's own product
  const Eigen::Vector3d expected = pose * Eigen::Vector3d(1.5, -2.0, 0.25);
  EXPECT_NEAR(b[0].x, expected.x(), 1e-12);
  EXPECT_NEAR(b[0].y, expected.y(), 1e-12);
  EXPECT_NEAR(b[0].z, expected.z(), 1e-12);
}

}  // namespace
}  // namespace trajroi::roi
