#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

#include "trajroi/roi/point.hpp"

namespace trajroi::roi {

// Naming: `a_from_b` maps coordinates given in frame b into frame a, so
// global_from_sensor = global_from_robot * robot_from_sensor  (ᴳp = ᴳ_R T · ᴿ_S T · ˢp).

// A planar pose as a 3-D isometry: translation (x_m, y_m, z_m), rotation yaw_rad about +z
// (counter-clockwise from +x, REP-103).
[[nodiscard]] Eigen::Isometry3d pose_from_xy_yaw(double x_m, double y_m, double yaw_rad, double z_m = 0.0);

// A sensor's mounting, a_from_b = T(xyz) · Rz(yaw) · Ry(pitch) · Rx(roll) (angles in rad).
[[nodiscard]] Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, double roll_rad, double pitch_rad,
                                                  double yaw_rad);

// A pose given as a translation and a unit quaternion (w, x, y, z), rebuilt always the same
// way (Quaterniond::toRotationMatrix, no renormalisation), so two programs that exchange these
// seven numbers transform points bit-identically.
[[nodiscard]] Eigen::Isometry3d pose_from_position_quaternion(const Eigen::Vector3d& position_m,
                                                              const Eigen::Quaterniond& orientation);

// out[i] = target_from_source · in[i] for every point, computed in double and stored in the
// output's precision; intensity is copied. `in` and `out` must have the same size and may be
// the same array (in-place). Allocates nothing. On a CPU with AVX, PointXYZI clouds take a
// vector path doing the same double operations in the same order (bit-identical results).
void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZI> in,
                      std::span<PointXYZI> out);
void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZd> in,
                      std::span<PointXYZd> out);
// The scalar code alone, whatever the CPU: the reference the vector path is tested against.
void transform_points_scalar(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZI> in,
                             std::span<PointXYZI> out);

// Where a decoder's point records keep what the filter takes: three floats x, y, z (m) at the
// record's start and an 8-bit intensity at `intensity_offset`; `stride_bytes` apart, at least 16.
struct RecordLayout {
  std::size_t stride_bytes = 0;
  std::size_t intensity_offset = 0;
};

// out[i] = target_from_source · (x, y, z) of record i, intensity converted to float: the same
// double operations in the same order as transform_points (bit-identical to copying the
// records into PointXYZI first and transforming those), without the copy. On a CPU with AVX,
// four records at a time. Allocates nothing.
void transform_records(const Eigen::Isometry3d& target_from_source, const std::byte* records, std::size_t count,
                       RecordLayout layout, PointXYZI* out);

// The same for a span of records of a standard-layout type whose first members are float x, y,
// z and which has a std::uint8_t `intensity`.
template <typename Record>
void transform_records(const Eigen::Isometry3d& target_from_source, std::span<const Record> in, PointXYZI* out) {
  static_assert(std::is_standard_layout_v<Record> && sizeof(Record) >= 16);
  static_assert(offsetof(Record, x) == 0 && offsetof(Record, y) == 4 && offsetof(Record, z) == 8);
  static_assert(std::is_same_v<decltype(Record::x), float> &&
                std::is_same_v<decltype(Record::intensity), std::uint8_t>);
  transform_records(target_from_source, reinterpret_cast<const std::byte*>(in.data()), in.size(),
                    RecordLayout{sizeof(Record), offsetof(Record, intensity)}, out);
}

}  // namespace trajroi::roi
