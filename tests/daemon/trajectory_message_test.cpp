// The trajectory input channel's checks on encoded messages: each kind of bad message gets
// its reason (a million waypoints, a hostile length field, truncated bytes, NaN, one point,
// an unknown frame, latitude/longitude out of range), and the limit itself is accepted.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "trajroi/daemon/messages.hpp"
#include "trajroi/trajectory_t.hpp"

namespace {

using trajroi::daemon::decode_trajectory;
using trajroi::daemon::kMaxMessageWaypoints;
using trajroi::daemon::TrajectoryReject;

const trajroi::pose::GlobalFrame& frame() {
  static const auto f = trajroi::pose::GlobalFrame::local_cartesian({48.1351, 11.5820, 520.0});
  return f;
}

std::vector<std::uint8_t> encode(const trajroi::trajectory_t& m) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_GT(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  return bytes;
}

trajroi::trajectory_t line(std::int32_t n, std::int8_t coordinates = trajroi::trajectory_t::GLOBAL_XY) {
  trajroi::trajectory_t m;
  m.id = 3;
  m.coordinates = coordinates;
  m.num_waypoints = n;
  for (std::int32_t i = 0; i < n; ++i) {
    m.u.push_back(coordinates == trajroi::trajectory_t::LAT_LON ? 48.1351 + 1e-6 * i : 0.1 * i);
    m.v.push_back(coordinates == trajroi::trajectory_t::LAT_LON ? 11.5820 : 0.0);
  }
  return m;
}

TrajectoryReject reason(const trajroi::trajectory_t& m) {
  const auto bytes = encode(m);
  return decode_trajectory(bytes.data(), bytes.size(), frame()).reason;
}

TEST(TrajectoryMessage, AMillionWaypointsIsRefusedAndTheLimitAccepted) {
  EXPECT_EQ(reason(line(1'000'000)), TrajectoryReject::kTooManyWaypoints);
  EXPECT_EQ(reason(line(kMaxMessageWaypoints + 1)), TrajectoryReject::kTooManyWaypoints);
  const auto bytes = encode(line(kMaxMessageWaypoints));
  const auto ok = decode_trajectory(bytes.data(), bytes.size(), frame());
  EXPECT_EQ(ok.reason, TrajectoryReject::kNone) << ok.detail;
  ASSERT_NE(ok.trajectory, nullptr);
  EXPECT_EQ(ok.trajectory->id, 3);
}

TEST(TrajectoryMessage, HostileOrCutBytesAreUndecodableWithoutAllocating) {
  auto bytes = encode(line(10));
  // num_waypoints (big-endian, after hash 8 · id 4 · coordinates 1) claims 2^31 − 1.
  bytes[13] = 0x7F;
  bytes[14] = bytes[15] = bytes[16] = 0xFF;
  EXPECT_EQ(decode_trajectory(bytes.data(), bytes.size(), frame()).reason, TrajectoryReject::kTooManyWaypoints);
  bytes[13] = 0xFF;  // negative
  EXPECT_EQ(decode_trajectory(bytes.data(), bytes.size(), frame()).reason, TrajectoryReject::kUndecodable);
  const auto whole = encode(line(10));
  for (const std::size_t cut : {std::size_t{0}, std::size_t{5}, std::size_t{17}, whole.size() - 1}) {
    EXPECT_EQ(decode_trajectory(whole.data(), cut, frame()).reason, TrajectoryReject::kUndecodable) << cut;
  }
  auto wrong_hash = encode(line(10));
  wrong_hash[0] ^= 0x01;
  EXPECT_EQ(decode_trajectory(wrong_hash.data(), wrong_hash.size(), frame()).reason, TrajectoryReject::kUndecodable);
}

TEST(TrajectoryMessage, EachBadContentHasItsReason) {
  auto nan = line(5);
  nan.v[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(reason(nan), TrajectoryReject::kNonFinite);
  EXPECT_EQ(reason(line(1)), TrajectoryReject::kTooFewWaypoints);
  auto same = line(4);
  for (auto& u : same.u)
    u = 2.0;
  EXPECT_EQ(reason(same), TrajectoryReject::kTooFewWaypoints);
  EXPECT_EQ(reason(line(5, 7)), TrajectoryReject::kBadCoordinates);
  auto north_of_pole = line(5, trajroi::trajectory_t::LAT_LON);
  north_of_pole.u[1] = 91.0;
  EXPECT_EQ(reason(north_of_pole), TrajectoryReject::kOutOfRange);
  EXPECT_EQ(reason(line(5, trajroi::trajectory_t::LAT_LON)), TrajectoryReject::kNone);
  auto zero_id = line(5);
  zero_id.id = 0;
  EXPECT_EQ(reason(zero_id), TrajectoryReject::kBadId);
}

}  // namespace
