#include "trajroi/pipeline/sweep.hpp"

#include <algorithm>
#include <utility>

#include "trajroi/host/memory.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::pipeline {
namespace {

// Makes an array's whole capacity resident (see Sweep::make_resident).
template <typename Array>
void make_capacity_resident(Array& a) {
  host::populate(a.data(), a.capacity() * sizeof(typename Array::value_type));
}

// Makes elements [from, to) of an array's capacity resident.
template <typename Array>
void make_range_resident(Array& a, std::size_t from, std::size_t to) {
  to = std::min(to, a.capacity());
  if (from < to) host::populate(a.data() + from, (to - from) * sizeof(typename Array::value_type));
}

}  // namespace

PublishedPose PublishedPose::from(const Eigen::Isometry3d& pose) {
  PublishedPose p;
  p.position_m = pose.translation();
  p.orientation = Eigen::Quaterniond(pose.linear()).normalized();
  if (p.orientation.w() < 0.0) p.orientation.coeffs() = -p.orientation.coeffs();
  return p;
}

Eigen::Isometry3d PublishedPose::isometry() const {
  return roi::pose_from_position_quaternion(position_m, orientation);
}

void PointColumns::reserve(std::size_t points) {
  if (points > x.capacity()) resident = 0;  // moved to new memory
  x.reserve(points);
  y.reserve(points);
  z.reserve(points);
  intensity.reserve(points);
  ring.reserve(points);
  return_type.reserve(points);
  time_offset_ns.reserve(points);
}

void PointColumns::swap(PointColumns& other) noexcept {
  x.swap(other.x);
  y.swap(other.y);
  z.swap(other.z);
  intensity.swap(other.intensity);
  ring.swap(other.ring);
  return_type.swap(other.return_type);
  time_offset_ns.swap(other.time_offset_ns);
  std::swap(resident, other.resident);
}

void PointColumns::make_resident() {
  clear();
  make_capacity_resident(x);
  make_capacity_resident(y);
  make_capacity_resident(z);
  make_capacity_resident(intensity);
  make_capacity_resident(ring);
  make_capacity_resident(return_type);
  make_capacity_resident(time_offset_ns);
  resident = x.capacity();
}

void PointColumns::make_resident_to(std::size_t points) {
  if (points <= resident) return;
  const std::size_t from = resident;
  const std::size_t to = std::min(x.capacity(), std::max(points, from + kResidentStep));
  make_range_resident(x, from, to);
  make_range_resident(y, from, to);
  make_range_resident(z, from, to);
  make_range_resident(intensity, from, to);
  make_range_resident(ring, from, to);
  make_range_resident(return_type, from, to);
  make_range_resident(time_offset_ns, from, to);
  resident = to;
}

void PointColumns::clear() noexcept {
  x.clear();
  y.clear();
  z.clear();
  intensity.clear();
  ring.clear();
  return_type.clear();
  time_offset_ns.clear();
}

void Sweep::take(Sweep& other) {
  static_cast<SweepHeader&>(*this) = other;
  PointColumns::swap(other);
  raw.swap(other.raw);
  raw_sensor_index.swap(other.raw_sensor_index);
  sensor_index.swap(other.sensor_index);
  point_index = other.point_index;  // kept for evaluations only: unreserved in the ring's slots
}

void Sweep::reserve(std::size_t points, std::size_t centre_count, std::size_t raw_points) {
  PointColumns::reserve(points);
  sensor_index.reserve(points);
  raw.reserve(raw_points);
  raw_sensor_index.reserve(raw_points);
  centres.reserve(centre_count);
}

void Sweep::make_resident() {
  clear_points();
  PointColumns::make_resident();
  make_capacity_resident(sensor_index);
  raw.make_resident();
  make_capacity_resident(raw_sensor_index);
}

void Sweep::make_resident_to(std::size_t points) {
  const std::size_t from = resident;
  PointColumns::make_resident_to(points);
  make_range_resident(sensor_index, from, resident);
}

void Sweep::clear_points() noexcept {
  PointColumns::clear();
  raw.clear();
  raw_sensor_index.clear();
  sensor_index.clear();
  point_index.clear();
}

}  // namespace trajroi::pipeline
