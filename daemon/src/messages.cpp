#include "trajroi/daemon/messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "trajroi/pipeline/pose_words.hpp"
#include "trajroi/pose/attitude.hpp"

namespace trajroi::daemon {
namespace {

template <typename T, typename Allocator>
void copy_into(std::vector<T>& out, const std::vector<T, Allocator>& in) {
  out.assign(in.begin(), in.end());
}

void set_pose(const pipeline::PublishedPose& p, double (&position)[3], double (&orientation)[4]) {
  for (int i = 0; i < 3; ++i)
    position[i] = p.position_m[i];
  orientation[0] = p.orientation.w();
  orientation[1] = p.orientation.x();
  orientation[2] = p.orientation.y();
  orientation[3] = p.orientation.z();
}

void store_be32(std::uint8_t* p, std::uint32_t v) noexcept {
  v = __builtin_bswap32(v);
  std::memcpy(p, &v, sizeof v);
}

// LCM's big-endian 32-bit elements (float bits as they are). Four at a time in SSE2, which
// every x86-64 has: GCC does not vectorise a byte swap for baseline x86-64, and with the
// arrays' ends read through the vector (a uint8_t store may alias them) the plain loop also
// reloaded them at every element: 4–7 % of an as-fast replay's CPU samples, 2 % now.
template <typename T, typename Allocator>
std::uint8_t* store_be32_array(std::uint8_t* out, const std::vector<T, Allocator>& values) noexcept {
  static_assert(sizeof(T) == sizeof(std::uint32_t));
  const T* const in = values.data();
  const std::size_t n = values.size();
  std::size_t i = 0;
#if defined(__SSE2__)
  for (; i + 4 <= n; i += 4) {
    __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i));
    v = _mm_or_si128(_mm_slli_epi16(v, 8), _mm_srli_epi16(v, 8));  // the bytes of each half swapped
    v = _mm_shufflehi_epi16(_mm_shufflelo_epi16(v, 0xB1), 0xB1);   // then the halves
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 4 * i), v);
  }
#endif
  for (; i < n; ++i) {
    std::uint32_t v;
    std::memcpy(&v, in + i, sizeof v);
    store_be32(out + 4 * i, v);
  }
  return out + 4 * n;
}

// Every field of points_t but the points.
void fill_points_head(const pipeline::SweepHeader& sweep, const DaemonConfig& config, trajroi::points_t& out) {
  out.sweep_index = static_cast<std::int64_t>(sweep.index);
  out.sweep_start_ns = sweep.start_ns;
  out.sweep_end_ns = sweep.end_ns;
  out.sweep_start_utc_ns = sweep.start_utc_ns;
  out.time_source = std::string(sweep.time_source);
  out.trajectory_id = sweep.trajectory_id;
  out.pose_mode =
      config.pose_mode == PoseMode::kPerSweep ? trajroi::points_t::POSE_PER_SWEEP : trajroi::points_t::POSE_PER_FIRING;
  out.return_mode = static_cast<std::int8_t>(sweep.return_mode);
  out.partial = sweep.partial;
  out.points_in = static_cast<std::int32_t>(sweep.points_in);
  out.lost_packets = static_cast<std::int32_t>(sweep.lost_packets);
  fill_pose(sweep, config, out.pose);
  set_pose(sweep.sensor, out.sensor_position_m, out.sensor_orientation);
}

}  // namespace

void fill_pose(const pipeline::SweepHeader& sweep, const DaemonConfig& config, trajroi::pose_t& out) {
  out.t_ns = sweep.pose_t_ns;
  out.sweep_index = static_cast<std::int64_t>(sweep.index);
  out.valid = sweep.pose_status == pose::PoseStatus::kValid;
  out.status = static_cast<std::int8_t>(sweep.pose_status);
  out.status_text = pipeline::pose_reason(sweep.pose_status, sweep.pose_measured, sweep.pose_limit, config);
  out.pose_source = std::string(pipeline::pose_source_name(config.pose_source));
  out.heading_source = std::string(sweep.heading_source);
  out.utc_ns = sweep.start_utc_ns;
  out.time_source = std::string(sweep.time_source);
  set_pose(sweep.robot, out.position_m, out.orientation);
  out.yaw_rad = out.valid ? pose::roll_pitch_yaw(sweep.robot.orientation).yaw_rad : 0.0;
  out.speed_mps = sweep.speed_mps;
  // A localization's or a fixed pose has no GNSS fix: those fields say "not applicable".
  const bool gnss = pipeline::uses_gnss(config.pose_source);
  out.fix_type = gnss ? static_cast<std::int8_t>(sweep.fix.fix_type) : trajroi::pose_t::NOT_APPLICABLE;
  out.rtk_fixed = gnss && sweep.fix.rtk_fixed;
  out.h_acc_m = gnss ? sweep.fix.h_acc_m : std::numeric_limits<double>::quiet_NaN();
}

// The sensors' names, and those the merge did not get.
void fill_sensors(const pipeline::SweepHeader& sweep, const DaemonConfig& config, bool told, trajroi::points_t& out) {
  out.sensor_names.clear();
  if (told) {
    for (const DaemonConfig::Lidar& l : config.lidars)
      out.sensor_names.push_back(l.name);
  }
  out.num_sensors = static_cast<std::int8_t>(out.sensor_names.size());
  out.missing.clear();
  for (std::size_t i = 0; i < config.lidars.size(); ++i) {
    if ((sweep.missing & (1U << i)) == 0) continue;
    if (!out.missing.empty()) out.missing += ", ";
    out.missing += config.lidars[i].name;
  }
}

void fill_points(const pipeline::Sweep& sweep, const DaemonConfig& config, trajroi::points_t& out) {
  fill_points_head(sweep, config, out);
  fill_sensors(sweep, config, true, out);
  out.num_points = static_cast<std::int32_t>(sweep.size());
  copy_into(out.x, sweep.x);
  copy_into(out.y, sweep.y);
  copy_into(out.z, sweep.z);
  copy_into(out.intensity, sweep.intensity);
  copy_into(out.ring, sweep.ring);
  copy_into(out.return_type, sweep.return_type);
  copy_into(out.time_offset_ns, sweep.time_offset_ns);
  out.sensor.assign(sweep.size(), 0);
  std::copy(sweep.sensor_index.begin(), sweep.sensor_index.end(), out.sensor.begin());
}

void encode_points(const pipeline::Sweep& sweep, const DaemonConfig& config, trajroi::points_t& head,
                   std::vector<std::uint8_t>& out) {
  encode_points(sweep, sweep, sweep.sensor_index, config, head, out);
}

void encode_points(const pipeline::SweepHeader& sweep, const pipeline::PointColumns& points,
                   std::span<const std::uint8_t> sensor_index, const DaemonConfig& config, trajroi::points_t& head,
                   std::vector<std::uint8_t>& out) {
  fill_points_head(sweep, config, head);
  fill_sensors(sweep, config, config.lidars.size() == 1 || sensor_index.size() == points.size(), head);
  head.num_points = 0;  // the arrays empty: num_points is the head's last field, patched below
  head.x.clear();
  head.y.clear();
  head.z.clear();
  head.intensity.clear();
  head.ring.clear();
  head.return_type.clear();
  head.time_offset_ns.clear();
  head.sensor.clear();
  const auto head_size = static_cast<std::size_t>(head.getEncodedSize());
  const std::size_t n = points.size();
  out.resize(head_size + n * kEncodedBytesPerPoint);
  std::uint8_t* p = out.data();
  (void)head.encode(p, 0, static_cast<int>(head_size));
  store_be32(p + head_size - 4, static_cast<std::uint32_t>(n));
  p += head_size;
  p = store_be32_array(p, points.x);
  p = store_be32_array(p, points.y);
  p = store_be32_array(p, points.z);
  p = std::copy(points.intensity.begin(), points.intensity.end(), p);
  p = std::copy(points.ring.begin(), points.ring.end(), p);
  p = std::copy(points.return_type.begin(), points.return_type.end(), p);
  p = store_be32_array(p, points.time_offset_ns);
  // The sensor of each point: all the one LiDAR's (0), or as the merge marked them.
  if (sensor_index.size() == n) {
    std::copy(sensor_index.begin(), sensor_index.end(), p);
  } else {
    std::fill_n(p, n, std::uint8_t{0});
  }
}

void fill_trajectory(const pipeline::ActiveTrajectory& trajectory, trajroi::trajectory_t& out) {
  const std::vector<Eigen::Vector2d>& w = trajectory.trajectory.waypoints();
  out.id = trajectory.id;
  out.coordinates = trajroi::trajectory_t::GLOBAL_XY;
  out.num_waypoints = static_cast<std::int32_t>(w.size());
  out.u.resize(w.size());
  out.v.resize(w.size());
  for (std::size_t i = 0; i < w.size(); ++i) {
    out.u[i] = w[i].x();
    out.v[i] = w[i].y();
  }
}

void fill_roi(const pipeline::Sweep& sweep, trajroi::roi_t& out) {
  out.sweep_index = static_cast<std::int64_t>(sweep.index);
  out.t_ns = sweep.start_ns;
  out.trajectory_id = sweep.trajectory_id;
  out.shape = sweep.shape == RoiShape::kCircular ? trajroi::roi_t::CIRCULAR : trajroi::roi_t::RECTANGULAR;
  out.radius_m = sweep.radius_m;
  out.height_m = sweep.height_m;
  out.width_m = sweep.width_m;
  out.spacing_m = sweep.spacing_m;
  out.start_s_m = sweep.start_s_m;
  out.look_ahead_m = sweep.look_ahead_m;
  const std::size_t n = sweep.centres.size();
  out.num_centres = static_cast<std::int32_t>(n);
  out.cx.resize(n);
  out.cy.resize(n);
  out.theta_rad.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.cx[i] = sweep.centres[i].position.x();
    out.cy[i] = sweep.centres[i].position.y();
    out.theta_rad[i] = sweep.centres[i].theta_rad;
  }
}

std::string_view to_string(TrajectoryReject reason) noexcept {
  switch (reason) {
    case TrajectoryReject::kNone:
      return "accepted";
    case TrajectoryReject::kBadId:
      return "id not positive";
    case TrajectoryReject::kBadCoordinates:
      return "unknown coordinates";
    case TrajectoryReject::kTooFewWaypoints:
      return "fewer than 2 distinct waypoints";
    case TrajectoryReject::kTooManyWaypoints:
      return "too many waypoints";
    case TrajectoryReject::kNonFinite:
      return "non-finite waypoint";
    case TrajectoryReject::kOutOfRange:
      return "latitude/longitude out of range";
    case TrajectoryReject::kUndecodable:
      return "undecodable message";
  }
  return "unknown";
}

TrajectoryCheck check_trajectory(const trajroi::trajectory_t& m, const pose::GlobalFrame& frame) {
  TrajectoryCheck r;
  const auto reject = [&r](TrajectoryReject reason, std::string detail) {
    r.reason = reason;
    r.detail = std::move(detail);
    return std::move(r);
  };
  if (m.id <= 0) return reject(TrajectoryReject::kBadId, "id " + std::to_string(m.id));
  if (m.coordinates != trajroi::trajectory_t::GLOBAL_XY && m.coordinates != trajroi::trajectory_t::LAT_LON) {
    return reject(TrajectoryReject::kBadCoordinates, "coordinates " + std::to_string(m.coordinates));
  }
  if (m.num_waypoints < 2)
    return reject(TrajectoryReject::kTooFewWaypoints, std::to_string(m.num_waypoints) + " waypoints");
  if (m.num_waypoints > kMaxMessageWaypoints) {
    return reject(TrajectoryReject::kTooManyWaypoints, std::to_string(m.num_waypoints) + " waypoints");
  }
  std::vector<Eigen::Vector2d> points;
  points.reserve(static_cast<std::size_t>(m.num_waypoints));
  for (std::size_t i = 0; i < static_cast<std::size_t>(m.num_waypoints); ++i) {
    const double u = m.u[i];
    const double v = m.v[i];
    if (!std::isfinite(u) || !std::isfinite(v)) {
      return reject(TrajectoryReject::kNonFinite, "waypoint " + std::to_string(i));
    }
    if (m.coordinates == trajroi::trajectory_t::GLOBAL_XY) {
      points.emplace_back(u, v);
      continue;
    }
    if (std::abs(u) > 90.0 || std::abs(v) > 180.0) {
      return reject(TrajectoryReject::kOutOfRange, "waypoint " + std::to_string(i));
    }
    try {
      points.push_back(frame.to_global(pose::Geodetic{u, v, 0.0}).head<2>());
    } catch (const std::exception& e) {
      return reject(TrajectoryReject::kOutOfRange, "waypoint " + std::to_string(i) + ": " + e.what());
    }
  }
  try {
    r.trajectory = std::make_unique<pipeline::ActiveTrajectory>(
        pipeline::ActiveTrajectory{roi::Trajectory(std::move(points)), m.id});
  } catch (const roi::TrajectoryError& e) {
    return reject(TrajectoryReject::kTooFewWaypoints, e.what());
  }
  return r;
}

}  // namespace trajroi::daemon

namespace trajroi::daemon {

TrajectoryReject precheck_trajectory_bytes(const void* data, std::size_t size) noexcept {
  // hash (8) · id (4) · coordinates (1) · num_waypoints (4, big-endian) · u[n] · v[n]
  constexpr std::size_t kHeader = 8 + 4 + 1 + 4;
  if (size < kHeader) return TrajectoryReject::kUndecodable;
  const auto* b = static_cast<const std::uint8_t*>(data);
  const auto n = static_cast<std::int32_t>(std::uint32_t{b[13]} << 24 | std::uint32_t{b[14]} << 16 |
                                           std::uint32_t{b[15]} << 8 | std::uint32_t{b[16]});
  if (n < 0) return TrajectoryReject::kUndecodable;
  if (n > kMaxMessageWaypoints) return TrajectoryReject::kTooManyWaypoints;
  if (size < kHeader + 16 * static_cast<std::size_t>(n)) return TrajectoryReject::kUndecodable;
  return TrajectoryReject::kNone;
}

TrajectoryCheck decode_trajectory(const void* data, std::size_t size, const pose::GlobalFrame& frame) {
  TrajectoryCheck r;
  r.reason = precheck_trajectory_bytes(data, size);
  if (r.reason != TrajectoryReject::kNone) {
    r.detail = std::to_string(size) + " bytes";
    return r;
  }
  try {
    trajroi::trajectory_t m;
    if (m.decode(data, 0, static_cast<int>(size)) < 0) {
      r.reason = TrajectoryReject::kUndecodable;
      r.detail = "bad fingerprint or length";
      return r;
    }
    return check_trajectory(m, frame);
  } catch (const std::exception& e) {
    r.reason = TrajectoryReject::kUndecodable;
    r.detail = e.what();
    return r;
  }
}

}  // namespace trajroi::daemon
