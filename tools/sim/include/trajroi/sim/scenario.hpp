#pragma once

// A simulation scenario: a world of primitives, the robot's path and speed, the sensors with
// their mountings, noise and faults, and the evaluation set-up (ROI sizes, keyframes). Read
// from YAML strictly: an unknown key, a missing field or an impossible value is an error
// naming the file, line, key and value (config/scenarios/factory.yaml documents every key).
//
// Frames as everywhere in trajroi: the global frame is ENU about `origin` (x east, y north,
// z up, the ground at z = 0); robot and sensor frames are REP-103; headings are
// counter-clockwise from +x.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "trajroi/pose/geodetic.hpp"
#include "trajroi/vlp16/packet.hpp"

namespace trajroi::sim {

// A box standing on the ground: centre (x, y), size along its own x and y, height, yaw.
struct Box {
  std::string name;
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d size_m = Eigen::Vector2d::Ones();
  double height_m = 1.0;
  double yaw_rad = 0.0;
  std::uint8_t reflectivity = 50;
};

// A vertical cylinder standing on the ground (pillars, trees, people).
struct Cylinder {
  std::string name;
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  double radius_m = 0.3;
  double height_m = 1.0;
  std::uint8_t reflectivity = 50;
};

struct WorldSpec {
  std::uint8_t ground_reflectivity = 20;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
};

// The path: from a start position and heading, straight lines and circular arcs in turn.
struct PathSegment {
  enum class Kind : std::uint8_t { kLine, kArc };
  Kind kind = Kind::kLine;
  double length_m = 0.0;  // line
  double radius_m = 0.0;  // arc
  double turn_rad = 0.0;  // arc: positive left (counter-clockwise), negative right
};

struct PathSpec {
  Eigen::Vector2d start_m = Eigen::Vector2d::Zero();
  double heading_rad = 0.0;
  std::vector<PathSegment> segments;
};

// A sensor's place on the robot: robot_from_sensor translation and yaw/pitch/roll.
struct Mounting {
  Eigen::Vector3d xyz_m = Eigen::Vector3d::Zero();
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double yaw_rad = 0.0;
  // robot_from_sensor = T(xyz) · Rz(yaw) · Ry(pitch) · Rx(roll).
  [[nodiscard]] Eigen::Isometry3d robot_from_sensor() const;
};

struct RobotSpec {
  double speed_mps = 0.5;
  double wait_before_s = 2.0;  // standing at the start (sensors settle, the pose fills)
  double wait_after_s = 1.0;   // standing at the end
  Mounting lidar{Eigen::Vector3d(0.0, 0.0, 0.7), 0.0, 0.0, 0.0};
  Eigen::Vector3d gnss_antenna_m = Eigen::Vector3d(0.0, 0.0, 0.9);
};

struct LidarSpec {
  double rpm = 600.0;  // 300 … 1200 (5 … 20 Hz)
  vlp16::ReturnMode return_mode = vlp16::ReturnMode::kStrongest;
  double min_range_m = 0.5;
  double max_range_m = 100.0;
  double range_noise_m = 0.0;      // standard deviation, along the ray
  double start_azimuth_deg = 0.0;  // at the first firing
};

// An interval of degraded GNSS: `lost` (NAV-PVT says no fix), `no_rtk` (3-D fix without
// carrier solution), `float` (RTK float), each with its own noise and reported accuracy.
struct GnssFault {
  enum class Kind : std::uint8_t { kLost, kNoRtk, kFloat };
  Kind kind = Kind::kLost;
  double from_s = 0.0;  // seconds after the first firing
  double to_s = 0.0;
  double noise_m = 0.0;
  double h_acc_m = 0.0;
};

struct GnssSpec {
  double rate_hz = 8.0;
  double latency_s = 0.02;  // epoch → first byte on the wire
  double baud = 115'200.0;
  double noise_h_m = 0.0;  // standard deviation of the horizontal error (first-order
  double noise_v_m = 0.0;  // Gauss–Markov, correlation time below), per axis
  double correlation_s = 10.0;
  double h_acc_m = 0.014;  // reported accuracy while healthy (RTK fixed)
  std::vector<GnssFault> faults;
};

struct ImuSpec {
  int rate_divisor = 13;  // VN-100 async output: 800 Hz / divisor (13: 61.5 Hz)
  double latency_s = 0.0;
  double baud = 115'200.0;
  double angle_noise_deg = 0.0;  // white noise on yaw, pitch, roll
  double gyro_noise_rps = 0.0;
  double accel_noise_mps2 = 0.0;
  double heading_bias_deg = 0.0;          // constant error of the reported yaw
  double magnetic_declination_deg = 0.0;  // the VN-100 reports magnetic yaw
};

// Bytes on the wire of one GNSS epoch (NAV-HPPOSLLH 36 + 8, NAV-PVT 92 + 8) and of one
// simulated VN-100 frame (sync, group, mask, TimeStartup 8, three 12-byte vectors, CRC).
inline constexpr std::size_t kGnssEpochBytes = 144;
inline constexpr std::size_t kImuFrameBytes = 50;

// From a sample's time to the host's receipt of its last byte (latency plus transmission at
// 10 bits a byte): the delay a consumer of the streams subtracts to stamp samples.
[[nodiscard]] inline double gnss_delay_s(const GnssSpec& g) noexcept {
  return g.latency_s + static_cast<double>(kGnssEpochBytes) * 10.0 / g.baud;
}
[[nodiscard]] inline double imu_delay_s(const ImuSpec& i) noexcept {
  return i.latency_s + static_cast<double>(kImuFrameBytes) * 10.0 / i.baud;
}

struct Keyframe {
  std::string name;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  double heading_rad = 0.0;
};

// The evaluation's set-up (the paper's Section III-B uses the factory values below).
struct EvaluationSpec {
  double circle_diameter_m = 28.0;
  double rect_height_m = 12.0;     // a, along the trajectory
  double rect_width_m = 28.0;      // b, across
  double look_ahead_m = 42.0;      // the ROI chain's length from the robot's projection
  double corridor_width_m = 28.0;  // the ground-truth corridor of truth/labels.bin
  double cuboid_length_m = 100.0;  // the long-cuboid baseline (Table 20)
  double cuboid_width_m = 12.0;
  double cuboid_height_m = 10.0;
  std::vector<Keyframe> keyframes;
};

struct Scenario {
  std::string name;
  std::uint64_t seed = 1;
  std::int64_t start_utc_ns = 0;  // first firing
  pose::Geodetic origin;          // of the global ENU frame
  WorldSpec world;
  PathSpec path;
  RobotSpec robot;
  LidarSpec lidar;
  GnssSpec gnss;
  ImuSpec imu;
  EvaluationSpec evaluation;
};

// Parses and validates a scenario; `source` names it in errors. Throws config::ConfigError.
[[nodiscard]] Scenario parse_scenario(std::string_view yaml_text, const std::string& source);
// Reads the file and parses it; throws config::ConfigError (also when it cannot be read).
[[nodiscard]] Scenario load_scenario(const std::filesystem::path& path);

// "2024-05-14T09:00:00Z" (optionally with fractional seconds) → ns since 1970; false if not
// that form or not a real date and time.
[[nodiscard]] bool parse_utc_iso8601(std::string_view text, std::int64_t& utc_ns);

}  // namespace trajroi::sim
