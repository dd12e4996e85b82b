// GNSS and IMU messages (built with the drivers' encoders) into the pose buffer: clock
// mapping, high-precision positions, invalid fixes and the attitude's frame.
#include "trajroi/pose_input/pose_input.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "test_data.hpp"
#include "trajroi/pose/attitude.hpp"
#include "trajroi/ublox/config.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::pose_input {
namespace {

TEST(ClockMap, TakesTheLeastDelayAndResetsOnAJump) {
  ClockMap clock(1'000'000'000);
  EXPECT_EQ(clock.map(1'000, 5'000), 5'000);  // offset 4000
  EXPECT_EQ(clock.map(2'000, 6'500), 6'000);  // 4500 > 4000: jitter ignored
  EXPECT_EQ(clock.map(3'000, 6'800), 6'800);  // offset 3800: the new floor
  EXPECT_EQ(clock.map(4'000, 8'000), 7'800);
  EXPECT_EQ(clock.resets(), 0u);
  EXPECT_EQ(clock.map(1'000, 9'000), 9'000);  // sensor time went backwards
  EXPECT_EQ(clock.resets(), 1u);
  EXPECT_EQ(clock.map(2'000, 3'000'000'000), 3'000'000'000);  // host jumped by 3 s
  EXPECT_EQ(clock.resets(), 2u);
}

// A 3-D, RTK-fixed NAV-PVT epoch at this latitude/longitude (50 m high, 14 mm accuracy).
ublox::NavPvt pvt(std::uint32_t itow_ms, double lat, double lon) {
  ublox::NavPvt m;
  m.itow_ms = itow_ms;
  m.fix_type_raw = 3;
  m.gnss_fix_ok = true;
  m.carr_soln = ublox::CarrierSolution::kFixed;
  m.lat_e7 = static_cast<std::int32_t>(std::llround(lat * 1e7));
  m.lon_e7 = static_cast<std::int32_t>(std::llround(lon * 1e7));
  m.height_mm = 50'000;
  m.h_acc_mm = 14;
  return m;
}

class PoseInputTest : public ::testing::Test {
 protected:
  PoseInputTest()
      : origin_{36.0, 127.0, 50.0},
        buffer_(pose::PoseGate{}, Eigen::Vector3d::Zero(), 64),
        input_(pose::GlobalFrame::local_cartesian(origin_), config(), buffer_) {}
  static PoseInputConfig config() {
    PoseInputConfig c;
    c.gnss_delay_ns = 30'000'000;
    return c;
  }
  pose::Geodetic origin_;
  pose::PoseBuffer buffer_;
  PoseInput input_;
};

TEST_F(PoseInputTest, HighPrecisionPositionOfTheSameEpochIsUsed) {
  // 1 m north of the origin in NAV-HPPOSLLH; NAV-PVT rounds it to 1e-7° (≈ 1.1 cm).
  const pose::GlobalFrame frame = pose::GlobalFrame::local_cartesian(origin_);
  const pose::Geodetic north = frame.to_geodetic({0.3, 1.0, 0.0});
  ublox::NavHpposllh hp;
  hp.itow_ms = 1000;
  const std::int64_t lat_e9 = std::llround(north.lat_deg * 1e9), lon_e9 = std::llround(north.lon_deg * 1e9);
  hp.lat_e7 = static_cast<std::int32_t>(lat_e9 / 100);
  hp.lat_hp_e9 = static_cast<std::int8_t>(lat_e9 % 100);
  hp.lon_e7 = static_cast<std::int32_t>(lon_e9 / 100);
  hp.lon_hp_e9 = static_cast<std::int8_t>(lon_e9 % 100);
  const std::int64_t h_e4 = std::llround(north.height_m * 1e4);
  hp.height_mm = static_cast<std::int32_t>(h_e4 / 10);
  hp.height_hp_e4m = static_cast<std::int8_t>(h_e4 % 10);
  hp.h_acc_e4m = 100;
  input_.gnss_bytes(ublox::encode_nav_hpposllh(hp), 5'000'000'000);
  input_.gnss_bytes(ublox::encode_nav_pvt(pvt(1000, north.lat_deg, north.lon_deg)), 5'040'000'000);
  EXPECT_EQ(input_.counters().fixes, 1u);
  EXPECT_EQ(input_.counters().high_precision, 1u);
  // The epoch: received 40 ms after... mapped back by the configured 30 ms delay.
  vn100::Sample s;
  s.set(vn100::Field::kTimeStartup);
  s.set(vn100::Field::kYawPitchRoll);
  s.ypr_deg = {0.0f, 0.0f, 0.0f};  // facing north
  for (int k = 0; k < 3; ++k) {
    s.time_startup_ns = static_cast<std::uint64_t>(4'900'000'000 + k * 100'000'000);
    input_.on_vn100(s, 4'900'000'000 + k * 100'000'000);
  }
  const pose::PoseQuery q = buffer_.pose_at(5'010'000'000);
  ASSERT_TRUE(q.valid()) << pose::to_string(q.status);
  EXPECT_NEAR(q.global_from_robot.translation().x(), 0.3, 1e-4);
  EXPECT_NEAR(q.global_from_robot.translation().y(), 1.0, 1e-4);
  // Facing true north: +90° in ENU.
  const double yaw = std::atan2(q.global_from_robot.linear()(1, 0), q.global_from_robot.linear()(0, 0));
  EXPECT_NEAR(yaw, std::numbers::pi / 2, 1e-6);
  EXPECT_FALSE(buffer_.pose_at(5'000'000'000).valid());  // before the epoch's mapped time
}

TEST_F(PoseInputTest, InvalidPositionKeepsTheLastOneWithItsFailingQuality) {
  input_.gnss_bytes(ublox::encode_nav_pvt(pvt(1000, 36.0, 127.0)), 1'030'000'000);
  ublox::NavPvt lost = pvt(1125, 0.0, 0.0);
  lost.fix_type_raw = 0;
  lost.gnss_fix_ok = false;
  lost.invalid_llh = true;
  input_.gnss_bytes(ublox::encode_nav_pvt(lost), 1'155'000'000);
  EXPECT_EQ(input_.counters().fixes, 2u);
  EXPECT_EQ(input_.counters().invalid_position, 1u);
  const std::vector<std::uint8_t> four_bytes{1, 2, 3, 4};
  const std::vector<std::uint8_t> short_pvt = ublox::encode_frame(0x01, 0x07, four_bytes);  // a 4-byte NAV-PVT
  input_.gnss_bytes(short_pvt, 1'200'000'000);
  EXPECT_EQ(input_.counters().malformed, 1u);
  EXPECT_EQ(input_.gnss_framing().checksum_errors, 0u);
}

// Found by the ubx fuzz target: a well-framed NAV-PVT whose latitude is −133.8° made the
// global-frame conversion throw out of the processing thread. It is counted and dropped, and
// the fixes around it still count.
TEST_F(PoseInputTest, APositionOffTheEllipsoidIsCountedNotThrown) {
  input_.gnss_bytes(ublox::encode_nav_pvt(pvt(1000, 36.0, 127.0)), 1'030'000'000);
  input_.gnss_bytes(ublox::encode_nav_pvt(pvt(1125, -133.791587, -40.86282)), 1'155'000'000);
  input_.gnss_bytes(ublox::encode_nav_pvt(pvt(1250, 36.0, 200.0)), 1'280'000'000);
  input_.gnss_bytes(ublox::encode_nav_pvt(pvt(1375, 36.00001, 127.0)), 1'405'000'000);
  EXPECT_EQ(input_.counters().invalid_position, 2u);
  EXPECT_EQ(input_.counters().fixes, 2u);
  const pose::GnssFix* newest = buffer_.newest_fix();
  ASSERT_NE(newest, nullptr);
  EXPECT_NEAR(newest->antenna_global_m.y(), 1.11, 0.01) << "0.00001° north of the origin";
}

// Yaw (rad, ENU) of the attitude the buffer holds at t.
double yaw_at(const pose::PoseBuffer& buffer, std::int64_t t_ns) {
  const pose::PoseQuery q = buffer.pose_at(t_ns);
  EXPECT_TRUE(q.valid()) << pose::to_string(q.status);
  return std::atan2(q.global_from_robot.linear()(1, 0), q.global_from_robot.linear()(0, 0));
}

// The VN-100 outputs people configure: YawPitchRoll, Quaternion or DCM alone, no time field
// (the data set's real logger). Each gives the same attitude, placed at its receive time minus
// the configured delay.
TEST(PoseInputImu, AnyAttitudeOutputWithoutATimeFieldGivesTheAttitude) {
  const pose::Geodetic origin{36.0, 127.0, 50.0};
  const Eigen::Quaterniond ned_from_frd = pose::ned_from_frd_ypr(30.0, 5.0, -3.0);
  const auto attitude = [&](vn100::Field field) {
    PoseInputConfig config;
    config.imu_delay_ns = 4'000'000;
    pose::PoseBuffer buffer(pose::PoseGate{}, Eigen::Vector3d::Zero(), 64);
    PoseInput input(pose::GlobalFrame::local_cartesian(origin), config, buffer);
    for (int k = 0; k < 3; ++k) {
      const ublox::NavPvt m = pvt(static_cast<std::uint32_t>(1000 + 100 * k), 36.0, 127.0);
      input.gnss_bytes(ublox::encode_nav_pvt(m), 1'000'000'000 + k * 100'000'000);
    }
    vn100::Sample s;
    s.set(field);
    s.ypr_deg = {30.0f, 5.0f, -3.0f};
    const Eigen::Quaterniond q = ned_from_frd;
    s.quaternion_xyzw = {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()),
                         static_cast<float>(q.w())};
    const Eigen::Matrix3d r = q.toRotationMatrix();
    for (int i = 0; i < 9; ++i)
      s.dcm[static_cast<std::size_t>(i)] = static_cast<float>(r(i / 3, i % 3));
    std::array<std::uint16_t, 8> groups{};
    groups[4] = field == vn100::Field::kYawPitchRoll ? 0x0002 : field == vn100::Field::kQuaternion ? 0x0004 : 0x0008;
    for (int k = 0; k < 3; ++k)
      input.imu_bytes(vn100::encode(s, groups), 1'004'000'000 + k * 100'000'000);
    EXPECT_EQ(input.counters().attitudes, 3u);
    EXPECT_EQ(input.counters().imu_receive_stamped, 3u);
    EXPECT_EQ(input.counters().imu_without_attitude, 0u);
    EXPECT_EQ(input.heading_source(), HeadingSource::kImu);
    const pose::PoseQuery at = buffer.pose_at(1'100'000'000);  // receive 1.104 s − 4 ms
    EXPECT_TRUE(at.valid()) << pose::to_string(at.status);
    return Eigen::Quaterniond(at.global_from_robot.linear());
  };
  const Eigen::Quaterniond from_ypr = attitude(vn100::Field::kYawPitchRoll);
  EXPECT_LT(from_ypr.angularDistance(attitude(vn100::Field::kQuaternion)), 1e-6);
  EXPECT_LT(from_ypr.angularDistance(attitude(vn100::Field::kDcm)), 1e-6);
}

// pose.source gnss: the course over ground above the speed, else the last heading held; before
// any, the configured initial heading.
// A moving base: NAV-RELPOSNED's relPosHeading (valid, accurate) of the same epoch is the
// heading, even parked; the baseline's direction in the robot frame is taken off.
TEST(PoseInputGnss, AMovingBaseBaselineGivesTheHeadingStandingStill) {
  const pose::Geodetic origin{36.0, 127.0, 50.0};
  PoseInputConfig config;
  config.attitude = AttitudeFrom::kGnss;
  config.heading.baseline_yaw_in_robot_rad = std::numbers::pi / 2;  // antennas mounted right → left
  pose::PoseBuffer buffer(pose::PoseGate{}, Eigen::Vector3d::Zero(), 64);
  PoseInput input(pose::GlobalFrame::local_cartesian(origin), config, buffer);
  for (int k = 0; k < 2; ++k) {
    // UBX-NAV-RELPOSNED version 1 (64 bytes), laid out by the F9 interface description:
    // iTOW at 4, relPosHeading (1e-5°) at 24, accHeading at 52, flags at 60 (gnssFixOK bit 0,
    // relPosValid bit 2, relPosHeadingValid bit 8). The baseline points north (heading 0).
    const auto itow = static_cast<std::uint32_t>(1000 + 100 * k);
    std::vector<std::uint8_t> payload(64, 0);
    payload[0] = 1;
    for (int b = 0; b < 4; ++b) {
      payload[static_cast<std::size_t>(4 + b)] = static_cast<std::uint8_t>(itow >> (8 * b));
      payload[static_cast<std::size_t>(52 + b)] = static_cast<std::uint8_t>(50'000U >> (8 * b));  // 0.5°
    }
    payload[60] = 0x05;
    payload[61] = 0x01;
    input.gnss_bytes(ublox::encode_frame(0x01, 0x3C, payload), 1'000'000'000 + k * 100'000'000);
    input.gnss_bytes(ublox::encode_nav_pvt(pvt(itow, 36.0, 127.0)), 1'000'000'000 + k * 100'000'000);
  }
  EXPECT_EQ(input.heading_source(), HeadingSource::kBaseline);
  // Baseline north (ENU yaw 90°) is the robot's left: the robot faces east (yaw 0).
  EXPECT_NEAR(yaw_at(buffer, 1'050'000'000), 0.0, 1e-6);
}

TEST(PoseInputGnss, HeadingFromTheCourseOverGroundHeldWhenSlow) {
  const pose::Geodetic origin{36.0, 127.0, 50.0};
  PoseInputConfig config;
  config.attitude = AttitudeFrom::kGnss;
  config.heading.min_speed_mps = 1.0;
  config.heading.max_heading_acc_deg = 5.0;
  config.initial_heading_deg = 180.0;  // facing south
  pose::PoseBuffer buffer(pose::PoseGate{}, Eigen::Vector3d::Zero(), 64);
  PoseInput input(pose::GlobalFrame::local_cartesian(origin), config, buffer);
  ublox::NavPvt m = pvt(0, 36.0, 127.0);
  const auto epoch = [&](int k, double speed_mps, double course_deg, double acc_deg) {
    m.itow_ms = static_cast<std::uint32_t>(1000 + 100 * k);
    m.ground_speed_mmps = static_cast<std::int32_t>(speed_mps * 1000.0);
    m.head_mot_e5deg = static_cast<std::int32_t>(course_deg * 1e5);
    m.head_acc_e5deg = static_cast<std::uint32_t>(acc_deg * 1e5);
    input.gnss_bytes(ublox::encode_nav_pvt(m), 1'000'000'000 + k * 100'000'000);
  };
  epoch(0, 0.1, 0.0, 90.0);  // parked: the configured heading
  epoch(1, 0.1, 0.0, 90.0);
  EXPECT_EQ(input.heading_source(), HeadingSource::kConfigured);
  EXPECT_NEAR(yaw_at(buffer, 1'050'000'000), -std::numbers::pi / 2, 1e-6);  // south
  epoch(2, 2.0, 90.0, 1.0);                                                 // driving east
  epoch(3, 2.0, 90.0, 1.0);
  EXPECT_EQ(input.heading_source(), HeadingSource::kCourse);
  EXPECT_NEAR(yaw_at(buffer, 1'250'000'000), 0.0, 1e-6);
  epoch(4, 0.2, 300.0, 60.0);  // stopped: the course is noise, the last heading is held
  EXPECT_EQ(input.heading_source(), HeadingSource::kHeld);
  EXPECT_NEAR(yaw_at(buffer, 1'350'000'000), 0.0, 1e-6);
  epoch(5, 2.0, 20.0, 10.0);  // fast but the course too uncertain: held
  EXPECT_EQ(input.heading_source(), HeadingSource::kHeld);
  EXPECT_EQ(input.counters().gnss_headings, 6u);
}

// The real VN-100 log (LoggerWavesInIce F00379, YawPitchRoll and DCM in every frame): the DCM
// as the frame carries it (row-major) is the rotation the yaw/pitch/roll give, Rz Ry Rx — the
// convention enu_from_vn_rotation() takes it in — to float rounding, in every one of the 8,895
// frames.
TEST(PoseInputImu, TheRealLogsDcmIsTheRotationOfItsYawPitchRoll) {
  TRAJROI_REQUIRE_DATA(raw, "vectornav/LoggerWavesInIce_F00379.raw");
  const std::string bytes = ::trajroi::test::read_file(raw);
  vn100::Framer framer;
  std::size_t frames = 0;
  double worst_rad = 0.0;
  framer.feed(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
              [&](std::span<const std::uint8_t> frame) {
                vn100::Sample s;
                ASSERT_TRUE(vn100::decode(frame, s));
                ASSERT_TRUE(s.has(vn100::Field::kYawPitchRoll) && s.has(vn100::Field::kDcm));
                Eigen::Matrix3d dcm;
                for (int i = 0; i < 9; ++i)
                  dcm(i / 3, i % 3) = static_cast<double>(s.dcm[static_cast<std::size_t>(i)]);
                const Eigen::Matrix3d ypr =
                    pose::ned_from_frd_ypr(static_cast<double>(s.ypr_deg[0]), static_cast<double>(s.ypr_deg[1]),
                                           static_cast<double>(s.ypr_deg[2]))
                        .toRotationMatrix();
                worst_rad = std::max(worst_rad, (dcm - ypr).cwiseAbs().maxCoeff());
                ++frames;
              });
  EXPECT_EQ(frames, 8895u);
  EXPECT_LT(worst_rad, 1e-4);
  std::printf("[ vn100 ] %zu real frames: DCM − Rz·Ry·Rx(YPR) at most %.2e\n", frames, worst_rad);
}

}  // namespace
}  // namespace trajroi::pose_input
