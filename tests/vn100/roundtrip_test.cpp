// The VN-100 encoder against the decoder: random samples survive encode → frame → decode
// bit for bit, for a selection covering every VN-100 field the decoder fills.
#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::vn100 {
namespace {

float random_float(std::mt19937& rng) {
  // Any finite bit pattern (NaN payloads would not compare equal to themselves).
  std::uniform_int_distribution<std::uint32_t> bits;
  for (;;) {
    const float f = std::bit_cast<float>(bits(rng));
    if (std::isfinite(f)) return f;
  }
}

template <std::size_t N>
void fill(std::array<float, N>& a, std::mt19937& rng) {
  for (float& f : a)
    f = random_float(rng);
}

template <std::size_t N>
void expect_same(const std::array<float, N>& a, const std::array<float, N>& b, const char* what) {
  for (std::size_t i = 0; i < N; ++i)
    EXPECT_EQ(std::bit_cast<std::uint32_t>(a[i]), std::bit_cast<std::uint32_t>(b[i])) << what << "[" << i << "]";
}

TEST(Vn100RoundTrip, RandomSamplesEveryField) {
  std::array<std::uint16_t, 8> fields{};
  fields[0] = 0x0001 | 0x0002 | 0x0004 | 0x0008 | 0x0010 | 0x0020 | 0x0100 | 0x0400 | 0x2000;  // Common
  fields[2] = 0x0001 | 0x0002 | 0x0004 | 0x0008 | 0x0040 | 0x0080;                             // IMU
  fields[4] = 0x0001 | 0x0008 | 0x0010 | 0x0020 | 0x0040 | 0x0080 | 0x0100;                    // Attitude
  std::mt19937 rng(5);
  for (int i = 0; i < 200; ++i) {
    Sample s;
    std::uniform_int_distribution<std::uint64_t> u64;
    s.time_startup_ns = u64(rng);
    s.time_gps_ns = u64(rng);
    s.time_sync_in_ns = u64(rng);
    fill(s.ypr_deg, rng);
    fill(s.quaternion_xyzw, rng);
    fill(s.angular_rate_rps, rng);
    fill(s.accel_mps2, rng);
    fill(s.mag_gauss, rng);
    s.temperature_c = random_float(rng);
    s.pressure_kpa = random_float(rng);
    fill(s.uncomp_mag_gauss, rng);
    fill(s.uncomp_accel_mps2, rng);
    fill(s.uncomp_gyro_rps, rng);
    s.delta_time_s = random_float(rng);
    fill(s.delta_theta_deg, rng);
    fill(s.delta_vel_mps, rng);
    fill(s.dcm, rng);
    fill(s.mag_ned_gauss, rng);
    fill(s.accel_ned_mps2, rng);
    fill(s.linear_accel_body_mps2, rng);
    fill(s.linear_accel_ned_mps2, rng);
    fill(s.ypr_uncertainty_deg, rng);
    s.vpe_status = static_cast<std::uint16_t>(u64(rng));
    s.imu_status = static_cast<std::uint16_t>(u64(rng));
    s.sync_in_count = static_cast<std::uint32_t>(u64(rng));

    const std::vector<std::uint8_t> frame = encode(s, fields);
    Framer framer;
    std::size_t frames = 0;
    Sample d;
    framer.feed(frame, [&](std::span<const std::uint8_t> f) {
      ++frames;
      ASSERT_TRUE(decode(f, d));
    });
    ASSERT_EQ(frames, 1U);
    EXPECT_EQ(d.time_startup_ns, s.time_startup_ns);
    EXPECT_EQ(d.time_gps_ns, s.time_gps_ns);
    EXPECT_EQ(d.time_sync_in_ns, s.time_sync_in_ns);
    EXPECT_EQ(d.sync_in_count, s.sync_in_count);
    EXPECT_EQ(d.vpe_status, s.vpe_status);
    EXPECT_EQ(d.imu_status, s.imu_status);
    expect_same(d.ypr_deg, s.ypr_deg, "ypr");
    expect_same(d.quaternion_xyzw, s.quaternion_xyzw, "quaternion");
    expect_same(d.angular_rate_rps, s.angular_rate_rps, "angular rate");
    expect_same(d.accel_mps2, s.accel_mps2, "accel");
    expect_same(d.mag_gauss, s.mag_gauss, "mag");
    expect_same(std::array<float, 2>{d.temperature_c, d.pressure_kpa},
                std::array<float, 2>{s.temperature_c, s.pressure_kpa}, "temp/pres");
    expect_same(d.uncomp_mag_gauss, s.uncomp_mag_gauss, "uncomp mag");
    expect_same(d.uncomp_accel_mps2, s.uncomp_accel_mps2, "uncomp accel");
    expect_same(d.uncomp_gyro_rps, s.uncomp_gyro_rps, "uncomp gyro");
    expect_same(std::array<float, 1>{d.delta_time_s}, std::array<float, 1>{s.delta_time_s}, "dtime");
    expect_same(d.delta_theta_deg, s.delta_theta_deg, "dtheta");
    expect_same(d.delta_vel_mps, s.delta_vel_mps, "dvel");
    expect_same(d.dcm, s.dcm, "dcm");
    expect_same(d.mag_ned_gauss, s.mag_ned_gauss, "mag ned");
    expect_same(d.accel_ned_mps2, s.accel_ned_mps2, "accel ned");
    expect_same(d.linear_accel_body_mps2, s.linear_accel_body_mps2, "linear accel body");
    expect_same(d.linear_accel_ned_mps2, s.linear_accel_ned_mps2, "linear accel ned");
    expect_same(d.ypr_uncertainty_deg, s.ypr_uncertainty_deg, "ypr uncertainty");
    if (HasFailure()) return;
  }
}

TEST(Vn100RoundTrip, TheLoggerSelectionReencodesItsFramesByteForByte) {
  // A frame built with the LoggerWavesInIce selection (IMU 0x003E, Attitude 0x003A), decoded
  // and encoded again, is the same bytes.
  std::array<std::uint16_t, 8> fields{};
  fields[2] = 0x003E;
  fields[4] = 0x003A;
  Sample s;
  s.ypr_deg = {135.9274F, -7.078407F, 14.22944F};
  s.temperature_c = 19.45568F;
  const std::vector<std::uint8_t> frame = encode(s, fields);
  ASSERT_EQ(frame.size(), 124U);
  Sample d;
  ASSERT_TRUE(decode(frame, d));
  EXPECT_EQ(encode(d, fields), frame);
  EXPECT_THROW((void)encode(s, std::array<std::uint16_t, 8>{0, 0, 0, 0x0001}), std::invalid_argument);
}

}  // namespace
}  // namespace trajroi::vn100
