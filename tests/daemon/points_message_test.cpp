// The points_t encoder that writes the arrays itself gives exactly the bytes of LCM's
// generated points_t::encode (the independent reference) for the same sweep, and those bytes
// decode back to the sweep's values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "trajroi/daemon/messages.hpp"

namespace {

// A sweep's array as the plain vector the message decodes to.
template <typename T, typename Allocator>
std::vector<T> plain(const std::vector<T, Allocator>& v) {
  return {v.begin(), v.end()};
}

using trajroi::daemon::PoseMode;
using trajroi::pipeline::Sweep;

trajroi::pipeline::Sweep sweep_with(std::size_t n) {
  trajroi::pipeline::Sweep s;
  s.index = 41;
  s.start_ns = 1'700'000'000'123'456'789;
  s.end_ns = s.start_ns + 199'000'000;
  s.start_utc_ns = 1'732'000'000'000'000'000;
  s.time_source = "vlp16_pps";
  s.partial = true;
  s.return_mode = 0x39;
  s.points_in = 57'600;
  s.lost_packets = 2;
  s.filtered = true;
  s.pose_status = trajroi::pose::PoseStatus::kValid;
  s.heading_source = "imu";
  s.trajectory_id = 7;
  s.robot.position_m = {12.5, -3.25, 0.5};
  s.sensor.position_m = {12.6, -3.25, 1.2};
  s.sensor.orientation = Eigen::Quaterniond(0.9, 0.1, -0.2, 0.3).normalized();
  for (std::size_t i = 0; i < n; ++i) {
    const auto f = static_cast<float>(i);
    // Signs, fractions, zero and negative zero, huge and tiny values: every byte of a float varies.
    s.x.push_back(i % 7 == 0 ? -0.0f : -1.5f * f + 0.1f);
    s.y.push_back(i % 11 == 0 ? std::numeric_limits<float>::max() : 3.0e-5f * f);
    s.z.push_back(i % 13 == 0 ? std::numeric_limits<float>::denorm_min() : -f / 3.0f);
    s.intensity.push_back(static_cast<std::uint8_t>(i * 37));
    s.ring.push_back(static_cast<std::uint8_t>(i % 16));
    s.return_type.push_back(static_cast<std::uint8_t>(1 + i % 3));
    s.time_offset_ns.push_back(static_cast<std::int32_t>(i * 2'304 + (i % 5 == 0 ? 0x7F000000 : 0)));
  }
  return s;
}

trajroi::daemon::DaemonConfig config_with(PoseMode mode) {
  trajroi::daemon::DaemonConfig c;
  c.pose_mode = mode;
  return c;
}

std::vector<std::uint8_t> reference_bytes(const trajroi::pipeline::Sweep& s, PoseMode mode) {
  trajroi::points_t m;
  trajroi::daemon::fill_points(s, config_with(mode), m);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

TEST(PointsMessage, TheDirectEncoderWritesLcmsBytes) {
  trajroi::points_t head;
  std::vector<std::uint8_t> bytes;
  // 0 and 1 point, odd sizes around vector widths, a dual-return sweep's worth; one `head` and
  // one buffer reused throughout, shrinking and growing, as the publisher reuses them.
  for (const std::size_t n : {std::size_t{1000}, std::size_t{0}, std::size_t{1}, std::size_t{15}, std::size_t{17},
                              std::size_t{33}, std::size_t{57'600}, std::size_t{3}}) {
    for (const PoseMode mode : {PoseMode::kPerFiring, PoseMode::kPerSweep}) {
      const trajroi::pipeline::Sweep s = sweep_with(n);
      trajroi::daemon::encode_points(s, config_with(mode), head, bytes);
      ASSERT_EQ(bytes, reference_bytes(s, mode)) << n << " points";
    }
  }
}

TEST(PointsMessage, TheBytesDecodeToTheSweep) {
  const trajroi::pipeline::Sweep s = sweep_with(101);
  trajroi::points_t head;
  std::vector<std::uint8_t> bytes;
  trajroi::daemon::encode_points(s, config_with(PoseMode::kPerFiring), head, bytes);
  trajroi::points_t m;
  ASSERT_EQ(m.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(m.sweep_index, 41);
  EXPECT_EQ(m.time_source, "vlp16_pps");
  EXPECT_EQ(m.points_in, 57'600);
  EXPECT_EQ(m.pose_mode, trajroi::points_t::POSE_PER_FIRING);
  ASSERT_EQ(m.num_points, 101);
  EXPECT_EQ(m.x, plain(s.x));
  EXPECT_TRUE(std::signbit(m.x[0]));
  EXPECT_EQ(m.y, plain(s.y));
  EXPECT_EQ(m.z, plain(s.z));
  EXPECT_EQ(m.intensity, plain(s.intensity));
  EXPECT_EQ(m.ring, plain(s.ring));
  EXPECT_EQ(m.return_type, plain(s.return_type));
  EXPECT_EQ(m.time_offset_ns, plain(s.time_offset_ns));
  EXPECT_DOUBLE_EQ(m.sensor_position_m[2], 1.2);
}

}  // namespace
