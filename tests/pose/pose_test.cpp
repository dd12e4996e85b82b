// Pose math: geodetic ↔ global frame, attitude conventions, the pose buffer and its gates.
// Reference values are computed here from textbook formulas, independently of GeographicLib.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "trajroi/pose/attitude.hpp"
#include "trajroi/pose/geodetic.hpp"
#include "trajroi/pose/pose_buffer.hpp"

namespace trajroi::pose {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kA = 6378137.0;            // WGS84 semi-major axis
constexpr double kF = 1.0 / 298.257223563;  // WGS84 flattening
constexpr double kE2 = kF * (2.0 - kF);

// Meridional radius of curvature at latitude φ.
double meridional_radius(double lat_rad) {
  return kA * (1.0 - kE2) / std::pow(1.0 - kE2 * std::sin(lat_rad) * std::sin(lat_rad), 1.5);
}
// Prime-vertical radius of curvature.
double normal_radius(double lat_rad) {
  return kA / std::sqrt(1.0 - kE2 * std::sin(lat_rad) * std::sin(lat_rad));
}

TEST(Geodetic, OriginMapsToZero) {
  const Geodetic origin{48.7409646, 9.3117369, 315.3};
  const GlobalFrame frame = GlobalFrame::local_cartesian(origin);
  const Eigen::Vector3d p = frame.to_global(origin);
  EXPECT_NEAR(p.norm(), 0.0, 1e-9);
}

TEST(Geodetic, ThousandthOfADegreeNorthIsAboutAHundredAndElevenMetres) {
  for (const double lat : {0.0, 30.0, 45.0, 60.0, -45.0}) {
    const GlobalFrame frame = GlobalFrame::local_cartesian({lat, 10.0, 0.0});
    const Eigen::Vector3d p = frame.to_global({lat + 0.001, 10.0, 0.0});
    // Arc length along the meridian; the chord differs by far less than a millimetre.
    const double expected_y = meridional_radius(lat * kDeg) * 0.001 * kDeg;
    EXPECT_NEAR(p.y(), expected_y, 1e-3) << "lat " << lat;
    EXPECT_NEAR(p.x(), 0.0, 1e-6) << "lat " << lat;
    EXPECT_NEAR(p.z(), -expected_y * expected_y / (2.0 * meridional_radius(lat * kDeg)), 1e-4) << "lat " << lat;
    if (lat == 45.0) {
      EXPECT_NEAR(p.y(), 111.13, 0.01);
    }
    if (lat == 0.0) {
      EXPECT_NEAR(p.y(), 110.57, 0.01);
    }
  }
}

TEST(Geodetic, ThousandthOfADegreeEastFollowsTheParallel) {
  const double lat = 45.0;
  const GlobalFrame frame = GlobalFrame::local_cartesian({lat, 10.0, 0.0});
  const Eigen::Vector3d p = frame.to_global({lat, 10.001, 0.0});
  EXPECT_NEAR(p.x(), normal_radius(lat * kDeg) * std::cos(lat * kDeg) * 0.001 * kDeg, 1e-3);
  EXPECT_GT(p.x(), 0.0);
}

TEST(Geodetic, HeightIsUp) {
  const GlobalFrame frame = GlobalFrame::local_cartesian({-34.9, 138.6, 25.0});
  EXPECT_NEAR(frame.to_global({-34.9, 138.6, 35.0}).z(), 10.0, 1e-9);
}

TEST(Geodetic, RoundTripBothFrames) {
  const Geodetic origin{55.6024871, 37.5979727, 206.121};
  const GlobalFrame local = GlobalFrame::local_cartesian(origin);
  const GlobalFrame utm = GlobalFrame::utm(37, true);
  for (const Geodetic& p : {Geodetic{55.61, 37.60, 200.0}, Geodetic{55.58, 37.55, 250.0}}) {
    for (const GlobalFrame* f : {&local, &utm}) {
      const Geodetic back = f->to_geodetic(f->to_global(p));
      EXPECT_NEAR(back.lat_deg, p.lat_deg, 1e-10);
      EXPECT_NEAR(back.lon_deg, p.lon_deg, 1e-10);
      EXPECT_NEAR(back.height_m, p.height_m, 1e-6);
    }
  }
}

TEST(Geodetic, UtmCentralMeridianAndEquator) {
  const GlobalFrame utm = GlobalFrame::utm(31, true);  // central meridian 3°E
  const Eigen::Vector3d p = utm.to_global({0.0, 3.0, 12.0});
  EXPECT_NEAR(p.x(), 500000.0, 1e-6);
  EXPECT_NEAR(p.y(), 0.0, 1e-6);
  EXPECT_NEAR(p.z(), 12.0, 1e-12);
  // Along the equator, easting grows by k0 · a · Δλ (to first order).
  const Eigen::Vector3d q = utm.to_global({0.0, 3.001, 0.0});
  EXPECT_NEAR(q.x() - 500000.0, 0.9996 * kA * 0.001 * kDeg, 1e-3);
  // A point of the southern hemisphere keeps a continuous (negative) northing.
  EXPECT_NEAR(utm.to_global({-0.001, 3.0, 0.0}).y(), -utm.to_global({0.001, 3.0, 0.0}).y(), 1e-6);
}

TEST(Geodetic, UtmConvergenceTurnsTrueBearings) {
  const GlobalFrame utm = GlobalFrame::utm(32, true);  // central meridian 9°E
  const Geodetic on_cm{48.0, 9.0, 0.0};
  EXPECT_NEAR(utm.global_yaw_from_true_bearing(0.0, on_cm), 90.0 * kDeg, 1e-12);
  // East of the central meridian grid north lies west of true north by γ ≈ Δλ·sin φ, so true
  // north appears rotated counter-clockwise in the grid.
  const Geodetic east{48.0, 11.0, 0.0};
  const double gamma = 2.0 * kDeg * std::sin(48.0 * kDeg);
  EXPECT_NEAR(utm.global_yaw_from_true_bearing(0.0, east), 90.0 * kDeg + gamma, 2e-4);
}

TEST(Geodetic, RejectsImpossibleConfiguration) {
  EXPECT_THROW((void)GlobalFrame::local_cartesian({91.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW((void)GlobalFrame::utm(61, true), std::invalid_argument);
  const GlobalFrame utm = GlobalFrame::utm(32, true);
  EXPECT_THROW((void)utm.to_global({48.0, 60.0, 0.0}), std::invalid_argument);  // far outside zone 32
}

// ---- Attitude ---------------------------------------------------------------------------------

Eigen::Vector3d forward(const Eigen::Quaterniond& q) {
  return q * Eigen::Vector3d::UnitX();
}
Eigen::Vector3d left(const Eigen::Quaterniond& q) {
  return q * Eigen::Vector3d::UnitY();
}
Eigen::Vector3d up(const Eigen::Quaterniond& q) {
  return q * Eigen::Vector3d::UnitZ();
}

TEST(Attitude, HeadingsAtTheFourCardinalPoints) {
  struct Case {
    double vn_yaw_deg;
    Eigen::Vector3d forward_enu;
    double enu_yaw_deg;
  };
  for (const Case& c : {Case{0.0, {0, 1, 0}, 90.0}, Case{90.0, {1, 0, 0}, 0.0}, Case{180.0, {0, -1, 0}, -90.0},
                        Case{270.0, {-1, 0, 0}, 180.0}}) {
    const Eigen::Quaterniond q = enu_from_vn_ypr(c.vn_yaw_deg, 0.0, 0.0);
    EXPECT_TRUE(forward(q).isApprox(c.forward_enu, 1e-12)) << c.vn_yaw_deg;
    EXPECT_TRUE(up(q).isApprox(Eigen::Vector3d::UnitZ(), 1e-12)) << c.vn_yaw_deg;
    EXPECT_NEAR(std::remainder(roll_pitch_yaw(q).yaw_rad - c.enu_yaw_deg * kDeg, 2 * M_PI), 0.0, 1e-12) << c.vn_yaw_deg;
    EXPECT_NEAR(std::remainder(enu_yaw_from_bearing_deg(c.vn_yaw_deg) - c.enu_yaw_deg * kDeg, 2 * M_PI), 0.0, 1e-12);
  }
  // Facing north, the robot's left is west.
  EXPECT_TRUE(left(enu_from_vn_ypr(0.0, 0.0, 0.0)).isApprox(Eigen::Vector3d(-1, 0, 0), 1e-12));
}

TEST(Attitude, PitchNoseUpAndRollRightDown) {
  // Facing east, nose up 10°: forward climbs.
  const Eigen::Quaterniond pitched = enu_from_vn_ypr(90.0, 10.0, 0.0);
  EXPECT_TRUE(forward(pitched).isApprox(Eigen::Vector3d(std::cos(10 * kDeg), 0, std::sin(10 * kDeg)), 1e-12));
  EXPECT_NEAR(roll_pitch_yaw(pitched).pitch_rad, -10.0 * kDeg, 1e-12);  // REP-103: nose up is negative
  // Facing east, right side down 20°: the left side rises.
  const Eigen::Quaterniond rolled = enu_from_vn_ypr(90.0, 0.0, 20.0);
  EXPECT_TRUE(left(rolled).isApprox(Eigen::Vector3d(0, std::cos(20 * kDeg), std::sin(20 * kDeg)), 1e-12));
  EXPECT_NEAR(roll_pitch_yaw(rolled).roll_rad, 20.0 * kDeg, 1e-12);
  // Combined: yaw, pitch and roll all come back.
  const RollPitchYaw rpy = roll_pitch_yaw(enu_from_vn_ypr(30.0, 5.0, -7.0));
  EXPECT_NEAR(rpy.yaw_rad, 60.0 * kDeg, 1e-12);
  EXPECT_NEAR(rpy.pitch_rad, -5.0 * kDeg, 1e-12);
  EXPECT_NEAR(rpy.roll_rad, -7.0 * kDeg, 1e-12);
}

TEST(Attitude, DeclinationAndMounting) {
  ImuMounting m;
  m.magnetic_declination_deg = 10.0;  // magnetic north is 10° east of true north
  EXPECT_NEAR(roll_pitch_yaw(enu_from_vn_ypr(0.0, 0.0, 0.0, m)).yaw_rad, 80.0 * kDeg, 1e-12);
  // IMU mounted turned left by 90° (its x is the robot's left): when the IMU faces north the
  // robot faces east.
  ImuMounting turned;
  turned.robot_from_imu = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(forward(enu_from_vn_ypr(0.0, 0.0, 0.0, turned)).isApprox(Eigen::Vector3d(1, 0, 0), 1e-12));
}

TEST(Attitude, FallbackHeadings) {
  const auto to_yaw = [](double bearing) { return enu_yaw_from_bearing_deg(bearing); };
  HeadingFallback cfg;
  cfg.min_speed_mps = 1.0;
  EXPECT_FALSE(yaw_from_course(90.0, 0.5, 1.0, cfg, to_yaw).valid);   // too slow
  EXPECT_FALSE(yaw_from_course(90.0, 2.0, 20.0, cfg, to_yaw).valid);  // too uncertain
  const HeadingCandidate course = yaw_from_course(90.0, 2.0, 1.0, cfg, to_yaw);
  ASSERT_TRUE(course.valid);
  EXPECT_NEAR(course.yaw_rad, 0.0, 1e-12);
  cfg.baseline_yaw_in_robot_rad = M_PI / 2;  // antennas mounted right → left
  const HeadingCandidate base = yaw_from_baseline(0.0, true, 0.5, cfg, to_yaw);
  ASSERT_TRUE(base.valid);
  EXPECT_NEAR(base.yaw_rad, 0.0, 1e-12);  // baseline points north, so the robot faces east
  EXPECT_FALSE(yaw_from_baseline(0.0, false, 0.5, cfg, to_yaw).valid);
}

// ---- Pose buffer ------------------------------------------------------------------------------

FixQuality good() {
  return {3, true, 0.02, true, false};
}

GnssFix fix(std::int64_t t_ms, double x, double y, FixQuality q = good()) {
  return {t_ms * 1'000'000, Eigen::Vector3d(x, y, 0.0), q};
}
AttitudeSample yaw_at(std::int64_t t_ms, double yaw_rad) {
  return {t_ms * 1'000'000, Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()))};
}

TEST(PoseBuffer, InterpolatesPositionAndSlerpsAttitude) {
  PoseBuffer buf(PoseGate{}, Eigen::Vector3d::Zero());
  ASSERT_TRUE(buf.add_fix(fix(0, 0.0, 0.0)));
  ASSERT_TRUE(buf.add_fix(fix(100, 1.0, 2.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(0, 0.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(100, M_PI / 2)));
  const PoseQuery q = buf.pose_at(25'000'000);
  ASSERT_TRUE(q.valid()) << to_string(q.status);
  EXPECT_TRUE(q.global_from_robot.translation().isApprox(Eigen::Vector3d(0.25, 0.5, 0.0), 1e-12));
  EXPECT_NEAR(roll_pitch_yaw(Eigen::Quaterniond(q.global_from_robot.linear())).yaw_rad, M_PI / 8, 1e-12);
}

// The buffer takes the attitude pair's part of the slerp once per sample: every interpolated
// attitude must still be exactly Eigen's slerp of the two samples (bit for bit), for pairs far
// apart, close together, identical, and on opposite hemispheres (negative dot product), in a
// ring that has wrapped.
TEST(PoseBuffer, AttitudesAreExactlyEigensSlerp) {
  PoseBuffer buf(PoseGate{}, Eigen::Vector3d::Zero(), 8);
  ASSERT_TRUE(buf.add_fix(fix(0, 0.0, 0.0)));
  std::vector<Eigen::Quaterniond> q;
  const auto turned = [](double roll, double pitch, double yaw) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
  };
  for (int i = 0; i < 20; ++i) {
    Eigen::Quaterniond next = turned(0.01 * i, -0.02 * i, 0.3 * i);
    if (i == 5) next = q.back();                                 // no rotation at all
    if (i == 6) next = turned(0.05, -0.1, 1.5 + 1e-9);           // a tiny step
    if (i % 4 == 3) next.coeffs() = -next.coeffs();              // the same rotation, other sign
    if (i == 10) next = Eigen::Quaterniond(0.6, 0.0, 0.8, 0.0);  // a large turn
    q.push_back(next);
    ASSERT_TRUE(buf.add_attitude({i * 10'000'000, next}));
  }
  ASSERT_TRUE(buf.add_fix(fix(1000, 0.0, 0.0)));
  for (int i = 12; i < 19; ++i) {  // the ring of 8 holds samples 12 … 19
    for (const double w : {0.0, 0.1, 0.5, 0.73, 0.999}) {
      const auto t = static_cast<std::int64_t>((i + w) * 10'000'000);
      const PoseQuery p = buf.pose_at(t);
      ASSERT_TRUE(p.valid()) << to_string(p.status);
      const double exact_w = static_cast<double>(t - i * 10'000'000) / 10'000'000.0;
      const Eigen::Matrix3d expected = q[static_cast<std::size_t>(i)]
                                           .normalized()
                                           .slerp(exact_w, q[static_cast<std::size_t>(i) + 1].normalized())
                                           .toRotationMatrix();
      EXPECT_EQ(p.global_from_robot.linear(), expected) << "sample " << i << " w " << w;
    }
  }
}

// A query held at the newest attitude (most of the daemon's: the IMU's frames come after the
// points they cover) takes the rotation and turned lever arm the attitude stored as it came;
// FiringPoses keeps the rotation's part of global_from_sensor while the attitude stays. Both
// must still be Eigen's own results bit for bit, through new attitudes, new fixes and a
// return to an attitude seen before.
TEST(FiringPoses, HeldAttitudesAndKeptRotationsAreEigensResultsBitForBit) {
  const Eigen::Vector3d lever(-0.2, 0.05, 0.9);
  PoseGate gate;
  gate.max_extrapolation_ns = 100'000'000;
  PoseBuffer buf(gate, lever, 16);
  const Eigen::Isometry3d robot_from_sensor =
      Eigen::Translation3d(0.1, -0.03, 0.7) * Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.3, -0.2, 0.9).normalized());
  FiringPoses firing(buf, robot_from_sensor, 55'296);
  const auto turned = [](double roll, double pitch, double yaw) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
  };
  std::vector<Eigen::Quaterniond> attitudes;
  std::vector<GnssFix> fixes;
  // The antenna at t: extrapolated from the last two fixes (held at the first one alone).
  const auto antenna_at = [&fixes](std::int64_t t) {
    const GnssFix& a = fixes.back();
    if (fixes.size() < 2) return a.antenna_global_m;
    const GnssFix& prev = fixes[fixes.size() - 2];
    const Eigen::Vector3d velocity =
        (a.antenna_global_m - prev.antenna_global_m) / static_cast<double>(a.t_ns - prev.t_ns);
    return Eigen::Vector3d(a.antenna_global_m + velocity * static_cast<double>(t - a.t_ns));
  };
  std::int64_t queries = 0;
  for (int k = 0; k < 12; ++k) {
    const std::int64_t t0 = k * 5'000'000;  // an IMU frame every 5 ms, a fix every 20 ms
    if (k % 4 == 0) {
      fixes.push_back(fix(t0 / 1'000'000, 0.3 * k, -0.1 * k));
      ASSERT_TRUE(buf.add_fix(fixes.back()));
    }
    const Eigen::Quaterniond q = k == 7 ? attitudes[3] : turned(0.01 * k, -0.005 * k, 0.7 + 0.04 * k);
    attitudes.push_back(q);
    ASSERT_TRUE(buf.add_attitude({t0, q}));
    firing.reset();  // a new query at t0 (its rotation part kept from before: the case to check)
    for (std::int64_t t = t0; t < t0 + 5'000'000; t += 55'296, ++queries) {  // held at this attitude
      const Eigen::Quaterniond held = q.normalized();
      PoseStatus status{};
      const Eigen::Isometry3d* pose = firing.at(t, status);
      ASSERT_NE(pose, nullptr) << to_string(status);
      const PoseQuery direct = buf.pose_at(t);
      ASSERT_TRUE(direct.valid());
      Eigen::Isometry3d robot = Eigen::Isometry3d::Identity();
      robot.linear() = held.toRotationMatrix();
      robot.translation() = antenna_at(t) - held * lever;
      ASSERT_EQ(direct.global_from_robot.matrix(), robot.matrix()) << "t " << t;
      const Eigen::Isometry3d expected = robot * robot_from_sensor;
      ASSERT_EQ(pose->matrix(), expected.matrix()) << "t " << t;
    }
  }
  EXPECT_GT(queries, 1000);
}

// Past the newest fix the position is extrapolated with the velocity from the fix before,
// only when that one passed the gate and came close enough before; else it is held.
TEST(PoseBuffer, ExtrapolatesOnlyFromAPreviousFixThatPassedAndWasClose) {
  PoseGate gate;
  gate.max_extrapolation_ns = 100'000'000;
  gate.max_gap_ns = 300'000'000;
  FixQuality bad = good();
  bad.fix_type = 1;
  for (const bool previous_passes : {true, false}) {
    for (const std::int64_t previous_ms : {0, -500}) {  // 100 ms before the newest, or 600 ms (a gap)
      PoseBuffer buf(gate, Eigen::Vector3d::Zero());
      ASSERT_TRUE(buf.add_attitude(yaw_at(140, 0.0)));  // held within the bound at 150 ms
      ASSERT_TRUE(buf.add_fix(fix(previous_ms, 0.0, 0.0, previous_passes ? good() : bad)));
      ASSERT_TRUE(buf.add_fix(fix(100, 1.0, -2.0)));
      const PoseQuery q = buf.pose_at(150'000'000);
      ASSERT_TRUE(q.valid()) << to_string(q.status);
      const bool extrapolates = previous_passes && previous_ms == 0;
      const Eigen::Vector3d expected = extrapolates ? Eigen::Vector3d(1.5, -3.0, 0.0) : Eigen::Vector3d(1.0, -2.0, 0.0);
      EXPECT_TRUE(q.global_from_robot.translation().isApprox(expected, 1e-12))
          << "previous passes " << previous_passes << ", at " << previous_ms
          << " ms: " << q.global_from_robot.translation().transpose();
    }
  }
}

TEST(PoseBuffer, LeverArmIsRotatedWithTheRobot) {
  PoseBuffer buf(PoseGate{}, Eigen::Vector3d(-0.5, 0.0, 1.2));  // antenna behind and above
  ASSERT_TRUE(buf.add_fix(fix(0, 10.0, 20.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(0, M_PI / 2)));  // facing +y
  const PoseQuery q = buf.pose_at(0);
  ASSERT_TRUE(q.valid());
  // The antenna is 0.5 m behind the robot, i.e. at −y: the robot is at y + 0.5.
  EXPECT_TRUE(q.global_from_robot.translation().isApprox(Eigen::Vector3d(10.0, 20.5, -1.2), 1e-12));
}

TEST(PoseBuffer, ExtrapolatesOnlyUpToTheBound) {
  PoseGate gate;
  gate.max_extrapolation_ns = 50'000'000;
  PoseBuffer buf(gate, Eigen::Vector3d::Zero());
  ASSERT_TRUE(buf.add_fix(fix(0, 0.0, 0.0)));
  ASSERT_TRUE(buf.add_fix(fix(100, 1.0, 0.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(0, 0.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(100, 0.0)));
  const PoseQuery inside = buf.pose_at(140'000'000);
  ASSERT_TRUE(inside.valid());
  EXPECT_NEAR(inside.global_from_robot.translation().x(), 1.4, 1e-12);  // constant velocity
  EXPECT_EQ(buf.pose_at(151'000'000).status, PoseStatus::kGnssTooOld);
  ASSERT_TRUE(buf.add_fix(fix(200, 2.0, 0.0)));
  EXPECT_EQ(buf.pose_at(151'000'000).status, PoseStatus::kAttitudeTooOld);
  EXPECT_EQ(buf.pose_at(-1).status, PoseStatus::kBeforeFirstSample);
}

TEST(PoseBuffer, EveryGateNamesItsReason) {
  struct Case {
    FixQuality quality;
    PoseGate gate;
    PoseStatus expected;
  };
  PoseGate rtk;
  rtk.require_rtk = RtkSolution::kFixed;
  PoseGate rtk_any;
  rtk_any.require_rtk = RtkSolution::kFloat;
  FixQuality two_d = good();
  two_d.fix_type = 2;
  FixQuality time_only = good();
  time_only.fix_type = 5;
  FixQuality not_ok = good();
  not_ok.gnss_fix_ok = false;
  FixQuality coarse = good();
  coarse.h_acc_m = 2.0;
  FixQuality rtk_float = good();
  rtk_float.rtk_fixed = false;
  rtk_float.rtk_float = true;
  FixQuality standalone = good();
  standalone.rtk_fixed = false;
  for (const Case& c :
       {Case{two_d, PoseGate{}, PoseStatus::kFixTypeTooLow}, Case{time_only, PoseGate{}, PoseStatus::kFixTypeTooLow},
        Case{not_ok, PoseGate{}, PoseStatus::kNoGnssFixOk}, Case{coarse, PoseGate{}, PoseStatus::kAccuracyTooLow},
        Case{rtk_float, rtk, PoseStatus::kRtkTooLow}, Case{rtk_float, PoseGate{}, PoseStatus::kValid},
        Case{rtk_float, rtk_any, PoseStatus::kValid}, Case{good(), rtk, PoseStatus::kValid},
        Case{standalone, rtk_any, PoseStatus::kRtkTooLow}, Case{standalone, PoseGate{}, PoseStatus::kValid}}) {
    PoseBuffer buf(c.gate, Eigen::Vector3d::Zero());
    ASSERT_TRUE(buf.add_fix(fix(0, 0.0, 0.0, c.quality)));
    ASSERT_TRUE(buf.add_attitude(yaw_at(0, 0.0)));
    EXPECT_EQ(buf.pose_at(0).status, c.expected) << to_string(c.expected);
  }
  // The withheld sweep's reason names the solution and the requirement.
  PoseBuffer buf(rtk, Eigen::Vector3d::Zero());
  ASSERT_TRUE(buf.add_fix(fix(0, 0.0, 0.0, rtk_float)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(0, 0.0)));
  const PoseQuery q = buf.pose_at(0);
  EXPECT_EQ(describe(q.status, q.measured, q.limit, PoseWords{}),
            "GNSS carrier solution float, fixed required (pose.require_rtk)");
}

TEST(PoseBuffer, ABadFixAfterAGoodOneInvalidatesTheSpanBetweenThem) {
  PoseBuffer buf(PoseGate{}, Eigen::Vector3d::Zero());
  FixQuality lost = good();
  lost.fix_type = 0;
  lost.gnss_fix_ok = false;
  ASSERT_TRUE(buf.add_fix(fix(0, 0.0, 0.0)));
  ASSERT_TRUE(buf.add_fix(fix(100, 0.0, 0.0, lost)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(0, 0.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(200, 0.0)));
  EXPECT_EQ(buf.pose_at(50'000'000).status, PoseStatus::kFixTypeTooLow);
  EXPECT_EQ(buf.pose_at(120'000'000).status, PoseStatus::kFixTypeTooLow);  // no stale pose after the loss
}

TEST(PoseBuffer, GapsEmptyBuffersAndOrdering) {
  PoseBuffer buf(PoseGate{}, Eigen::Vector3d::Zero(), 4);
  EXPECT_EQ(buf.pose_at(0).status, PoseStatus::kNoGnss);
  ASSERT_TRUE(buf.add_fix(fix(0, 0.0, 0.0)));
  EXPECT_EQ(buf.pose_at(0).status, PoseStatus::kNoAttitude);
  ASSERT_TRUE(buf.add_fix(fix(3000, 1.0, 0.0)));  // 3 s later: a gap
  ASSERT_TRUE(buf.add_attitude(yaw_at(0, 0.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(3000, 0.0)));
  EXPECT_EQ(buf.pose_at(1'000'000'000).status, PoseStatus::kGnssGap);
  EXPECT_FALSE(buf.add_fix(fix(3000, 1.0, 0.0)));  // same time: refused
  EXPECT_FALSE(buf.add_fix(fix(100, 1.0, 0.0)));   // older: refused
  EXPECT_FALSE(buf.add_fix(fix(4000, std::nan(""), 0.0)));
  EXPECT_EQ(buf.counters().out_of_order, 2U);
  EXPECT_EQ(buf.counters().non_finite, 1U);
  // Capacity 4: the oldest samples go first.
  for (int i = 4; i < 10; ++i)
    ASSERT_TRUE(buf.add_fix(fix(1000 * i, 0.0, 0.0)));
  ASSERT_TRUE(buf.add_attitude(yaw_at(9000, 0.0)));
  EXPECT_EQ(buf.pose_at(3'500'000'000).status, PoseStatus::kBeforeFirstSample);
  EXPECT_THROW(PoseBuffer(PoseGate{}, Eigen::Vector3d::Zero(), 1), std::invalid_argument);
}

}  // namespace
}  // namespace trajroi::pose
