// Encoders against decoders: random messages survive encode → frame → decode unchanged.
#include <gtest/gtest.h>

#include <random>

#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"

namespace trajroi::ublox {
namespace {

template <class T>
T any(std::mt19937& rng) {
  return static_cast<T>(
      std::uniform_int_distribution<std::int64_t>(std::numeric_limits<T>::min(), std::numeric_limits<T>::max())(rng));
}

// Every message goes through the framer too, so the checksum is checked.
std::vector<std::uint8_t> payload_of(const std::vector<std::uint8_t>& frame) {
  Framer framer;
  std::vector<std::uint8_t> payload;
  framer.feed(frame, [&](const Message& m) { payload.assign(m.payload.begin(), m.payload.end()); });
  EXPECT_EQ(framer.counters().frames, 1U);
  return payload;
}

TEST(UbxRoundTrip, RandomNavPvt) {
  std::mt19937 rng(11);
  for (int i = 0; i < 500; ++i) {
    NavPvt m;
    m.itow_ms = any<std::uint32_t>(rng);
    m.year = any<std::uint16_t>(rng);
    m.month = any<std::uint8_t>(rng);
    m.day = any<std::uint8_t>(rng);
    m.hour = any<std::uint8_t>(rng);
    m.minute = any<std::uint8_t>(rng);
    m.second = any<std::uint8_t>(rng);
    m.valid_date = (i & 1) != 0;
    m.valid_time = (i & 2) != 0;
    m.fully_resolved = (i & 4) != 0;
    m.time_accuracy_ns = any<std::uint32_t>(rng);
    m.nano_ns = any<std::int32_t>(rng);
    m.fix_type_raw = static_cast<std::uint8_t>(i % 6);
    m.gnss_fix_ok = (i & 8) != 0;
    m.diff_soln = (i & 16) != 0;
    m.carr_soln = static_cast<CarrierSolution>(i % 3);
    m.head_veh_valid = (i & 32) != 0;
    m.num_sv = any<std::uint8_t>(rng);
    m.lon_e7 = any<std::int32_t>(rng);
    m.lat_e7 = any<std::int32_t>(rng);
    m.height_mm = any<std::int32_t>(rng);
    m.hmsl_mm = any<std::int32_t>(rng);
    m.h_acc_mm = any<std::uint32_t>(rng);
    m.v_acc_mm = any<std::uint32_t>(rng);
    m.vel_n_mmps = any<std::int32_t>(rng);
    m.vel_e_mmps = any<std::int32_t>(rng);
    m.vel_d_mmps = any<std::int32_t>(rng);
    m.ground_speed_mmps = any<std::int32_t>(rng);
    m.head_mot_e5deg = any<std::int32_t>(rng);
    m.speed_acc_mmps = any<std::uint32_t>(rng);
    m.head_acc_e5deg = any<std::uint32_t>(rng);
    m.pdop_e2 = any<std::uint16_t>(rng);
    m.invalid_llh = (i & 64) != 0;
    m.has_head_veh = true;
    m.head_veh_e5deg = any<std::int32_t>(rng);
    const auto d = decode_nav_pvt(payload_of(encode_nav_pvt(m)));
    ASSERT_TRUE(d.ok());
    ASSERT_EQ(d.value, m) << "message " << i;
  }
}

TEST(UbxRoundTrip, RandomNavHpposllh) {
  std::mt19937 rng(12);
  for (int i = 0; i < 500; ++i) {
    NavHpposllh m;
    m.version = static_cast<std::uint8_t>(i % 2);
    m.invalid_llh = (i & 2) != 0;
    m.itow_ms = any<std::uint32_t>(rng);
    m.lon_e7 = any<std::int32_t>(rng);
    m.lat_e7 = any<std::int32_t>(rng);
    m.height_mm = any<std::int32_t>(rng);
    m.hmsl_mm = any<std::int32_t>(rng);
    m.lon_hp_e9 = any<std::int8_t>(rng);
    m.lat_hp_e9 = any<std::int8_t>(rng);
    m.height_hp_e4m = any<std::int8_t>(rng);
    m.hmsl_hp_e4m = any<std::int8_t>(rng);
    m.h_acc_e4m = any<std::uint32_t>(rng);
    m.v_acc_e4m = any<std::uint32_t>(rng);
    const auto d = decode_nav_hpposllh(payload_of(encode_nav_hpposllh(m)));
    ASSERT_TRUE(d.ok());
    ASSERT_EQ(d.value, m) << "message " << i;
  }
}

}  // namespace
}  // namespace trajroi::ublox
