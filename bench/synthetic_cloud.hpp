#pragma once

// A synthetic VLP-16-like scene for benchmarks: 16 rings from −15° to +15° every 2°, 1800
// firings per revolution (0.2°, 10 Hz), seen from a sensor 1 m above the ground in a factory
// aisle: ground plane, walls 8 m either side and 60 m ahead and behind, and on the left a row
// of racks 2.5 m from the path (5 m of rack, 5 m of gap). With the paper's ROI sizes about a
// third of the points fall inside the chain. The robot drives along +x; the trajectory goes
// straight and then turns left.
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <vector>

#include "trajroi/roi/point.hpp"
#include "trajroi/roi/trajectory.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::bench {

inline constexpr int kRings = 16;
inline constexpr int kFiringsPerRevolution = 1800;
inline constexpr double kSensorHeight_m = 1.0;
inline constexpr double kAisleHalfWidth_m = 8.0;
inline constexpr double kRackOffset_m = 2.5;  // racks on the left, x ∈ [10k, 10k + 5) m
inline constexpr double kEndWall_m = 60.0;

// One revolution in the sensor frame (REP-103), every return present.
inline std::vector<roi::PointXYZI> synthetic_frame() {
  std::vector<roi::PointXYZI> frame;
  frame.reserve(kRings * kFiringsPerRevolution);
  for (int f = 0; f < kFiringsPerRevolution; ++f) {
    const double az = 2.0 * std::numbers::pi * f / kFiringsPerRevolution;
    const double cx = std::cos(az);
    const double sy = std::sin(az);
    for (int ring = 0; ring < kRings; ++ring) {
      const double el = (-15.0 + 2.0 * ring) * std::numbers::pi / 180.0;
      const double horizontal = std::cos(el);
      double range = 100.0;
      if (el < 0.0) range = std::min(range, kSensorHeight_m / std::sin(-el));
      if (std::abs(sy) > 1e-9) range = std::min(range, kAisleHalfWidth_m / (std::abs(sy) * horizontal));
      if (sy > 1e-9) {
        const double to_rack = kRackOffset_m / (sy * horizontal);
        if (std::fmod(std::fmod(to_rack * horizontal * cx, 10.0) + 10.0, 10.0) < 5.0) {
          range = std::min(range, to_rack);
        }
      }
      if (std::abs(cx) > 1e-9) range = std::min(range, kEndWall_m / (std::abs(cx) * horizontal));
      frame.push_back({static_cast<float>(range * horizontal * cx), static_cast<float>(range * horizontal * sy),
                       static_cast<float>(range * std::sin(el)), static_cast<float>(ring)});
    }
  }
  return frame;
}

// The robot's path in the global frame: 40 m along +x, then a left turn of radius 15 m.
inline roi::Trajectory synthetic_trajectory() {
  std::vector<Eigen::Vector2d> w{{-10.0, 0.0}, {30.0, 0.0}};
  for (int k = 1; k <= 30; ++k) {
    const double a = std::numbers::pi / 2.0 * k / 30.0;
    w.emplace_back(30.0 + 15.0 * std::sin(a), 15.0 - 15.0 * std::cos(a));
  }
  return roi::Trajectory(std::move(w));
}

// `frames` revolutions in the global frame, the robot advancing 0.05 m along +x per frame
// (0.5 m/s at 10 Hz), concatenated.
inline std::vector<roi::PointXYZI> accumulated_cloud(int frames) {
  const std::vector<roi::PointXYZI> frame = synthetic_frame();
  const Eigen::Isometry3d robot_from_sensor = roi::pose_from_xy_yaw(0.0, 0.0, 0.0, kSensorHeight_m);
  std::vector<roi::PointXYZI> cloud(frame.size() * static_cast<std::size_t>(frames));
  for (int k = 0; k < frames; ++k) {
    const Eigen::Isometry3d global_from_robot = roi::pose_from_xy_yaw(0.05 * k, 0.0, 0.0);
    roi::transform_points(
        global_from_robot * robot_from_sensor, frame,
        std::span<roi::PointXYZI>(cloud).subspan(frame.size() * static_cast<std::size_t>(k), frame.size()));
  }
  return cloud;
}

}  // namespace trajroi::bench
