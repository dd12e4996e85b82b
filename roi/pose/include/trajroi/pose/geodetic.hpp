#pragma once

// Geodetic coordinates (WGS84 latitude, longitude, ellipsoidal height) to and from the
// global frame every point is placed in. Two choices, fixed by configuration:
//  - LocalCartesian: x east, y north, z up (ENU), metres, about a configured origin; the
//    origin maps to (0, 0, 0). Exact (GeographicLib::LocalCartesian, via ECEF).
//  - UTM/UPS in a configured zone: x easting, y northing (false origins removed: x is metres
//    from the central meridian, y from the equator, negative south), z ellipsoidal height.
// Headings: ENU yaw is counter-clockwise from +x. A true bearing (clockwise from true north)
// at a point converts with global_yaw_from_true_bearing(), which includes the rotation of the
// point's local north within the global frame (UTM meridian convergence; the small tilt of
// north away from the origin for LocalCartesian).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>

namespace trajroi::pose {

struct Geodetic {
  double lat_deg = 0;
  double lon_deg = 0;
  double height_m = 0;  // above the WGS84 ellipsoid
};

class GlobalFrame {
 public:
  // Throws std::invalid_argument for an origin outside ±90° latitude or ±180° longitude.
  static GlobalFrame local_cartesian(const Geodetic& origin);
  // zone 1 … 60, or 0 for UPS (then `northern` picks the pole). Throws for another zone.
  static GlobalFrame utm(int zone, bool northern);

  GlobalFrame(const GlobalFrame&);
  GlobalFrame& operator=(const GlobalFrame&);
  GlobalFrame(GlobalFrame&&) noexcept;
  GlobalFrame& operator=(GlobalFrame&&) noexcept;
  ~GlobalFrame();

  // Throws std::invalid_argument when a UTM/UPS point cannot be put in the configured zone
  // (more than the projection's limits away from it).
  [[nodiscard]] Eigen::Vector3d to_global(const Geodetic& point) const;
  [[nodiscard]] Geodetic to_geodetic(const Eigen::Vector3d& global_m) const;

  // Rotation taking vectors in the local ENU frame at `point` into the global frame's axes.
  [[nodiscard]] Eigen::Matrix3d global_from_local_enu(const Geodetic& point) const;
  // ENU yaw (rad, counter-clockwise from global +x) of a direction whose true bearing at
  // `point` is `bearing_deg` (clockwise from true north).
  [[nodiscard]] double global_yaw_from_true_bearing(double bearing_deg, const Geodetic& point) const;

  [[nodiscard]] bool is_utm() const noexcept;

 private:
  struct Impl;
  explicit GlobalFrame(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace trajroi::pose
