#include "trajroi/daemon/sweep_processor.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <numbers>
#include <stdexcept>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "trajroi/config/text_file.hpp"
#include "trajroi/framing/little_endian.hpp"
#include "trajroi/pose_input_t.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::daemon {
namespace {

// Points filtered together: those of three packets or more (384 at most each).
constexpr std::size_t kScratchPoints = 1024;
// The speed is the distance to the pose this long before, over the time. The pose must have
// been valid at every sweep start since then: right after a gap in the pose (a GNSS outage)
// the shorter baselines are tried, and in the first 0.1 s none (the speed is unknown).
constexpr std::array<std::int64_t, 3> kSpeedBaselines_ns{500'000'000, 200'000'000, 100'000'000};
constexpr double kMaxAdvancePerSweep_m = 10.0;  // projection search window (50 m/s at 5 Hz)
// Farther than this from the windowed projection, the robot is not where the window assumed
// (its pose jumped: relocalised, carried, a replay looping): the whole trajectory is searched.
constexpr double kReacquireDistance_m = 5.0;

vlp16::Calibration load_calibration(const std::filesystem::path& file) {
  if (file.empty()) return vlp16::Calibration::vlp16_default();
  return vlp16::parse_calibration_yaml(config::read_text_file(file), file.string());
}

vlp16::StreamOptions stream_options(const DaemonConfig& c) {
  vlp16::StreamOptions o;
  o.decode.min_range_m = c.lidar.min_range_m;
  o.decode.max_range_m = c.lidar.max_range_m;
  o.cut_azimuth_deg = c.lidar.cut_azimuth_deg;
  return o;
}

double size_along(const DaemonConfig::Roi& r) {
  return r.shape == RoiShape::kCircular ? r.circle_diameter_m : r.rect_height_m;
}

// The decoder's points as the filter takes them (x, y, z, intensity), in the sensor's frame.
void copy_for_filter(std::span<const vlp16::Point> in, roi::PointXYZI* out) noexcept {
  for (const vlp16::Point& p : in)
    *out++ = roi::PointXYZI{p.x, p.y, p.z, static_cast<float>(p.intensity)};
}

#if defined(__x86_64__) || defined(__i386__)
// Row i of global_from_sensor applied to four points: ((r_i0 x + r_i1 y) + r_i2 z) + t_i.
__attribute__((target("avx"))) inline __m128 transformed_row(const Eigen::Isometry3d& global_from_sensor,
                                                             Eigen::Index i, __m256d x, __m256d y, __m256d z) noexcept {
  const Eigen::Matrix3d& r = global_from_sensor.linear();
  const __m256d sum =
      _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(r(i, 0)), x), _mm256_mul_pd(_mm256_set1_pd(r(i, 1)), y));
  return _mm256_cvtpd_ps(_mm256_add_pd(_mm256_add_pd(sum, _mm256_mul_pd(_mm256_set1_pd(r(i, 2)), z)),
                                       _mm256_set1_pd(global_from_sensor.translation()(i))));
}

// copy_for_filter then roi::transform_points in one pass, four points at a time: their x, y
// and z side by side (a transpose of the records), each coordinate's products and sums in
// transform_points' order, in doubles, without fused multiply-adds (none in this target), so
// every coordinate rounds exactly as there. Places the whole fours and answers how many.
__attribute__((target("avx"))) std::size_t place_fours_avx(const Eigen::Isometry3d& global_from_sensor,
                                                           std::span<const vlp16::Point> in,
                                                           roi::PointXYZI* out) noexcept {
  static_assert(offsetof(vlp16::Point, x) == 0 && offsetof(vlp16::Point, y) == 4 && offsetof(vlp16::Point, z) == 8 &&
                sizeof(vlp16::Point) >= 16);
  std::size_t i = 0;
  for (; i + 4 <= in.size(); i += 4, out += 4) {
    const vlp16::Point* p = &in[i];
    __m128 a = _mm_loadu_ps(&p[0].x);  // x y z distance
    __m128 b = _mm_loadu_ps(&p[1].x);
    __m128 c = _mm_loadu_ps(&p[2].x);
    __m128 d = _mm_loadu_ps(&p[3].x);
    _MM_TRANSPOSE4_PS(a, b, c, d);  // a: four x, b: four y, c: four z
    const __m256d x = _mm256_cvtps_pd(a);
    const __m256d y = _mm256_cvtps_pd(b);
    const __m256d z = _mm256_cvtps_pd(c);
    __m128 gx = transformed_row(global_from_sensor, 0, x, y, z);
    __m128 gy = transformed_row(global_from_sensor, 1, x, y, z);
    __m128 gz = transformed_row(global_from_sensor, 2, x, y, z);
    __m128 gi = _mm_cvtepi32_ps(_mm_setr_epi32(p[0].intensity, p[1].intensity, p[2].intensity, p[3].intensity));
    _MM_TRANSPOSE4_PS(gx, gy, gz, gi);
    _mm_storeu_ps(&out[0].x, gx);
    _mm_storeu_ps(&out[1].x, gy);
    _mm_storeu_ps(&out[2].x, gz);
    _mm_storeu_ps(&out[3].x, gi);
  }
  return i;
}
#endif

// Points of one pose into the global frame, as the filter takes them: whole fours in one AVX
// pass where the processor has it, the rest copied and transformed.
void place(const Eigen::Isometry3d& global_from_sensor, std::span<const vlp16::Point> in, roi::PointXYZI* out) {
  std::size_t done = 0;
#if defined(__x86_64__) || defined(__i386__)
  if (__builtin_cpu_supports("avx")) done = place_fours_avx(global_from_sensor, in, out);
#endif
  const std::span<const vlp16::Point> rest = in.subspan(done);
  copy_for_filter(rest, out + done);
  const std::span<roi::PointXYZI> placed(out + done, rest.size());
  roi::transform_points(global_from_sensor, placed, placed);
}

// Writes one element in every page of an empty array's capacity, so that its memory is
// resident (see Sweep::make_resident).
template <typename Array>
void touch_capacity(Array& a) {
  a.resize(a.capacity());  // default-initialised: nothing written yet
  constexpr std::size_t kStride = 4096 / sizeof(typename Array::value_type);
  for (std::size_t i = 0; i < a.size(); i += kStride)
    a[i] = typename Array::value_type{};
  a.clear();
}

}  // namespace

pose_input::PoseInputConfig pose_input_config(const DaemonConfig& c) {
  pose_input::PoseInputConfig p;
  p.imu.robot_from_imu = c.robot_from_imu;
  p.imu.magnetic_declination_deg = c.magnetic_declination_deg;
  p.gnss_delay_ns = std::llround(c.gnss.delay_s * 1e9);
  p.imu_delay_ns = std::llround(c.imu.delay_s * 1e9);
  p.attitude = c.pose_source == PoseSource::kGnss ? pose_input::AttitudeFrom::kGnss : pose_input::AttitudeFrom::kImu;
  p.heading.min_speed_mps = c.gnss_heading.min_speed_mps;
  p.heading.max_heading_acc_deg = c.gnss_heading.max_heading_acc_deg;
  p.heading.baseline_yaw_in_robot_rad = c.gnss_heading.baseline_yaw_deg * std::numbers::pi / 180.0;
  p.initial_heading_deg = c.gnss_heading.initial_heading_deg;
  return p;
}

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

void Sweep::take(Sweep& other) {
  static_cast<SweepHeader&>(*this) = other;
  x.swap(other.x);
  y.swap(other.y);
  z.swap(other.z);
  intensity.swap(other.intensity);
  ring.swap(other.ring);
  return_type.swap(other.return_type);
  time_offset_ns.swap(other.time_offset_ns);
  point_index = other.point_index;  // kept for evaluations only: unreserved in the ring's slots
}

void Sweep::reserve(std::size_t points, std::size_t centre_count) {
  x.reserve(points);
  y.reserve(points);
  z.reserve(points);
  intensity.reserve(points);
  ring.reserve(points);
  return_type.reserve(points);
  time_offset_ns.reserve(points);
  centres.reserve(centre_count);
}

void Sweep::make_resident() {
  clear_points();
  touch_capacity(x);
  touch_capacity(y);
  touch_capacity(z);
  touch_capacity(intensity);
  touch_capacity(ring);
  touch_capacity(return_type);
  touch_capacity(time_offset_ns);
}

void Sweep::clear_points() noexcept {
  x.clear();
  y.clear();
  z.clear();
  intensity.clear();
  ring.clear();
  return_type.clear();
  time_offset_ns.clear();
  point_index.clear();
}

// Routes the stream decoder's callbacks to the processor and on to the caller's sink.
class SweepProcessor::FrameAdapter final : public vlp16::FrameSink {
 public:
  FrameAdapter(SweepProcessor& processor, SweepSink& sink) : processor_(processor), sink_(sink) {}
  void on_points(const vlp16::Frame& frame, std::size_t first) override { processor_.add_points(frame, first, sink_); }
  void on_frame(const vlp16::Frame& frame) override { processor_.end_sweep(frame, sink_); }

 private:
  SweepProcessor& processor_;
  SweepSink& sink_;
};

SweepProcessor::SweepProcessor(const DaemonConfig& config, std::unique_ptr<ActiveTrajectory> trajectory)
    : config_(config),
      decoder_(load_calibration(config.lidar.calibration), stream_options(config)),
      // A localization's pose is the robot origin's own: no lever arm.
      poses_(config.gate, config.pose_source == PoseSource::kLcm ? Eigen::Vector3d::Zero() : config.gnss_antenna_m,
             config.pose_capacity),
      pose_input_(pose::GlobalFrame::local_cartesian(config.origin), pose_input_config(config), poses_),
      firing_(
          poses_, config.lidar.robot_from_lidar,
          config.pose_mode == PoseMode::kPerSweep ? std::numeric_limits<std::int64_t>::max() : vlp16::kFiringCycle_ns),
      active_(std::move(trajectory)),
      circles_(config.roi.circle_diameter_m / 2.0, {}, roi::ZLimits{config.roi.z_min_m, config.roi.z_max_m}),
      rects_(config.roi.rect_height_m, config.roi.rect_width_m, {},
             roi::ZLimits{config.roi.z_min_m, config.roi.z_max_m}) {
  if (!active_) throw std::invalid_argument("SweepProcessor: no trajectory");
  if (config_.pose_source == PoseSource::kFixed) poses_.hold(config_.fixed_pose);
  // Preallocate and touch: the largest chain the look-ahead can need, its grid, the sweep.
  const DaemonConfig::Roi& r = config_.roi;
  const double longest = r.look_ahead_m + r.max_speed_mps * r.look_ahead_per_mps_s;
  const auto centres = static_cast<std::size_t>(longest / (r.spacing_ratio * size_along(r))) + 2;
  sweep_.reserve(config_.buffers.max_points_per_sweep, centres);
  scratch_.resize(kScratchPoints);  // used as [0, batch): never resized (value-initialising) after
  kept_.reserve(kScratchPoints);
  roi::place_centres(active_->trajectory, 0.0, longest, r.spacing_ratio * size_along(r), sweep_.centres);
  // The configured shape's only: the other is never used (start-up is part of a replay's time).
  if (config_.roi.shape == RoiShape::kCircular) {
    circles_.assign(sweep_.centres);
    circle_grid_.build(circles_);
  } else {
    rects_.assign(sweep_.centres);
    rect_grid_.build(rects_);
  }
  sweep_.centres.clear();
}

SweepProcessor::~SweepProcessor() = default;

roi::ScanCalibration SweepProcessor::calibrate_scan() const {
  return config_.roi.shape == RoiShape::kCircular ? circle_grid_.calibrate() : rect_grid_.calibrate();
}

void SweepProcessor::lidar_datagram(LidarPort port, std::span<const std::uint8_t> payload, std::int64_t receive_ns,
                                    SweepSink& sink, const vlp16::DecodedPacket* decoded) {
  if (port == LidarPort::kPosition) {
    decoder_.on_position_packet(payload);
    return;
  }
  FrameAdapter adapter(*this, sink);
  decoder_.on_data_packet(payload, receive_ns, adapter, decoded);
}

double SweepProcessor::host_minus_gnss_utc_s() const noexcept {
  const auto& gnss = pose_input_.gnss_utc();
  if (!gnss || !host_utc_offset_ns_) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(gnss->host_ns + *host_utc_offset_ns_ - gnss->utc_ns) * 1e-9;
}

void SweepProcessor::pose_message(std::span<const std::uint8_t> bytes, std::int64_t receive_ns) {
  (void)receive_ns;  // the message carries its own time
  trajroi::pose_input_t m;
  if (bytes.size() < 8 ||
      m.decode(bytes.data() + 8, 0, static_cast<int>(bytes.size() - 8)) != static_cast<int>(bytes.size() - 8)) {
    ++counters_.pose_messages_malformed;
    return;
  }
  const auto utc_minus_monotonic = static_cast<std::int64_t>(framing::le_u64(bytes, 0));
  pose_input::ExternalPose p;
  if (m.clock == trajroi::pose_input_t::STAMP_UTC) {
    p.t_ns = m.t_ns - utc_minus_monotonic;
  } else if (m.clock == trajroi::pose_input_t::STAMP_MONOTONIC) {
    p.t_ns = m.t_ns;
  } else {
    ++counters_.pose_messages_malformed;
    return;
  }
  if (m.frame != trajroi::pose_input_t::GLOBAL_XY && m.frame != trajroi::pose_input_t::LAT_LON) {
    ++counters_.pose_messages_malformed;
    return;
  }
  p.lat_lon = m.frame == trajroi::pose_input_t::LAT_LON;
  p.position = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
  p.orientation = Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  p.valid = m.valid;
  pose_input_.on_external_pose(p);
}

void SweepProcessor::flush(SweepSink& sink) {
  FrameAdapter adapter(*this, sink);
  decoder_.flush(adapter);
}

void SweepProcessor::keep_point_indices() {
  keep_indices_ = true;
  sweep_.point_index.reserve(config_.buffers.max_points_per_sweep);
}

void SweepProcessor::offer_trajectory(std::unique_ptr<ActiveTrajectory> trajectory) {
  if (pending_) retired_ = std::move(pending_);
  pending_ = std::move(trajectory);
}

std::unique_ptr<ActiveTrajectory> SweepProcessor::take_retired() noexcept {
  return std::move(retired_);
}

void SweepProcessor::start_sweep(const vlp16::Frame& frame) {
  in_sweep_ = true;
  if (pending_) {
    retired_ = std::move(active_);
    active_ = std::move(pending_);
    have_hint_ = false;
    ++counters_.trajectory_swaps;
  }
  const DaemonConfig::Roi& r = config_.roi;
  Sweep& s = sweep_;
  s.clear_points();
  s.centres.clear();
  s.truncated = 0;
  s.start_ns = frame.start_time_ns;
  if (frame.start_utc_ns) {
    s.start_utc_ns = *frame.start_utc_ns;
    s.time_source = "vlp16_pps";
  } else if (host_utc_offset_ns_) {
    s.start_utc_ns = frame.start_time_ns + *host_utc_offset_ns_;
    s.time_source = "host";
  } else {
    s.start_utc_ns = 0;
    s.time_source = "none";
  }
  s.pose_t_ns = frame.start_time_ns;
  s.trajectory_id = active_->id;
  s.shape = r.shape;
  s.speed_mps = 0.0;
  const pose::GnssFix* fix = poses_.newest_fix();
  s.fix = fix != nullptr ? fix->quality : pose::FixQuality{};
  s.fix_t_ns = fix != nullptr ? fix->t_ns : 0;
  firing_.reset();

  const pose::PoseQuery q = poses_.pose_at(frame.start_time_ns);
  s.pose_status = q.status;
  s.heading_source =
      config_.pose_source == PoseSource::kFixed ? "fixed" : pose_input::to_string(pose_input_.heading_source());
  s.pose_measured = q.measured;
  s.pose_limit = q.limit;
  s.filtered = q.valid();
  if (!s.filtered) {
    have_hint_ = false;
    valid_since_ns_.reset();
    return;
  }
  s.robot = PublishedPose::from(q.global_from_robot);
  s.sensor = PublishedPose::from(s.robot.isometry() * config_.lidar.robot_from_lidar);
  sweep_sensor_pose_ = s.sensor.isometry();
  const Eigen::Vector2d position = q.global_from_robot.translation().head<2>();
  s.speed_known = false;
  if (!valid_since_ns_) valid_since_ns_ = frame.start_time_ns;
  for (const std::int64_t baseline : kSpeedBaselines_ns) {
    if (frame.start_time_ns - baseline < *valid_since_ns_) continue;
    const pose::PoseQuery before = poses_.pose_at(frame.start_time_ns - baseline);
    if (before.valid()) {
      s.speed_mps =
          (position - before.global_from_robot.translation().head<2>()).norm() / (static_cast<double>(baseline) * 1e-9);
      s.speed_known = true;
      break;
    }
  }

  const roi::Trajectory& trajectory = active_->trajectory;
  roi::Projection p =
      have_hint_ ? trajectory.project(position, s_hint_m_, kMaxAdvancePerSweep_m) : trajectory.project(position);
  if (have_hint_ && p.distance_m > kReacquireDistance_m) {
    const roi::Projection anywhere = trajectory.project(position);
    if (anywhere.distance_m < p.distance_m) {
      p = anywhere;
      ++counters_.projection_reacquired;
    }
  }
  s_hint_m_ = p.s_m;
  have_hint_ = true;
  trajectory_distance_m_ = p.distance_m;
  // An unknown speed grows the ROI as the cap does: the larger region is the safe side.
  const double speed = s.speed_known ? std::min(s.speed_mps, r.max_speed_mps) : r.max_speed_mps;
  s.start_s_m = p.s_m;
  s.look_ahead_m = r.look_ahead_m + speed * r.look_ahead_per_mps_s;
  const double grow = speed * r.width_per_mps_s;
  if (r.shape == RoiShape::kCircular) {
    s.radius_m = (r.circle_diameter_m + grow) / 2.0;
    s.height_m = 0.0;
    s.width_m = 0.0;
    s.spacing_m = roi::spacing_from_ratio(r.spacing_ratio, r.circle_diameter_m + grow);
    roi::place_centres(trajectory, s.start_s_m, s.look_ahead_m, s.spacing_m, s.centres);
    circles_.assign(s.centres, s.radius_m);
    circle_grid_.build(circles_);
  } else {
    s.radius_m = 0.0;
    s.height_m = r.rect_height_m;
    s.width_m = r.rect_width_m + grow;
    s.spacing_m = roi::spacing_from_ratio(r.spacing_ratio, r.rect_height_m);
    roi::place_centres(trajectory, s.start_s_m, s.look_ahead_m, s.spacing_m, s.centres);
    rects_.assign(s.centres, s.height_m, s.width_m);
    rect_grid_.build(rects_);
  }
}

void SweepProcessor::add_points(const vlp16::Frame& frame, std::size_t first, SweepSink& sink) {
  if (first == 0 || !in_sweep_) {
    start_sweep(frame);
    unfiltered_from_ = first;
  }
  sweep_.last_packet_arrival_ns = arrival_ns_;
  // The points wait until a whole batch has come (a few packets, a millisecond or two of the
  // sensor's): the scan and the placing are set up once per batch, not per packet (as-fast
  // replay of the dual-return corridor: processing thread 12 % less). Their firings' poses
  // are taken then, from the GNSS and IMU samples received until then, in the order of
  // arrival as before (one that came meanwhile interpolates where it was extrapolated). The
  // sweep's end filters the rest.
  filter_points(frame, kScratchPoints, sink);
}

void SweepProcessor::filter_points(const vlp16::Frame& frame, std::size_t at_least, SweepSink& sink) {
  const std::size_t end = frame.points.size();
  for (; unfiltered_from_ < end && end - unfiltered_from_ >= at_least && sweep_.filtered;
       unfiltered_from_ = std::min(end, unfiltered_from_ + kScratchPoints)) {
    const std::size_t i = unfiltered_from_;
    const pose::PoseStatus status = filter_batch(frame, i, std::min(end, i + kScratchPoints), sink);
    if (status != pose::PoseStatus::kValid) {
      sweep_.filtered = false;
      sweep_.pose_status = status;
      sweep_.pose_measured = firing_.measured();
      sweep_.pose_limit = firing_.limit();
      sweep_.clear_points();
      have_hint_ = false;
    }
  }
}

pose::PoseStatus SweepProcessor::filter_batch(const vlp16::Frame& frame, std::size_t first, std::size_t end,
                                              SweepSink& sink) {
  const auto place_run = [&](std::size_t from, std::size_t to, const Eigen::Isometry3d& global_from_lidar) {
    place(global_from_lidar, std::span(frame.points).subspan(from, to - from), scratch_.data() + (from - first));
  };
  if (config_.pose_mode == PoseMode::kPerSweep) {
    place_run(first, end, sweep_sensor_pose_);
  } else {
    // Per firing: the points of one firing period (in time order) share a pose.
    for (std::size_t i = first; i < end;) {
      pose::PoseStatus status{};
      const Eigen::Isometry3d* pose = firing_.at(frame.start_time_ns + frame.points[i].time_offset_ns, status);
      if (pose == nullptr) return status;
      // The following points the same pose covers, in the frame's time offsets.
      const pose::FiringPoses::Window window = firing_.window_after(frame.start_time_ns);
      std::size_t j = i + 1;
      while (j < end && window.contains(frame.points[j].time_offset_ns))
        ++j;
      place_run(i, j, *pose);
      i = j;
    }
  }
  const std::span<const roi::PointXYZI> placed(scratch_.data(), end - first);
  sink.on_placed(frame, first, placed);
  if (config_.roi.shape == RoiShape::kCircular) {
    (void)circle_grid_.filter(placed, kept_);
  } else {
    (void)rect_grid_.filter(placed, kept_);
  }
  Sweep& s = sweep_;
  const std::size_t room =
      config_.buffers.max_points_per_sweep - std::min(config_.buffers.max_points_per_sweep, s.size());
  const std::size_t n = std::min(room, kept_.size());
  s.truncated += static_cast<std::uint32_t>(kept_.size() - n);
  // Grown once, then written through pointers (push_back would store each array's end at
  // every point: the compiler cannot tell the arrays apart).
  const std::size_t at = s.size();
  const auto grown = [at, n](auto& v) {
    v.resize(at + n);
    return v.data() + at;
  };
  float* const x = grown(s.x);
  float* const y = grown(s.y);
  float* const z = grown(s.z);
  std::uint8_t* const intensity = grown(s.intensity);
  std::uint8_t* const ring = grown(s.ring);
  std::uint8_t* const return_type = grown(s.return_type);
  std::int32_t* const time_offset_ns = grown(s.time_offset_ns);
  // The sources in locals too: every byte stored may alias anything, so the compiler would
  // reload the vectors' data pointers after each one.
  const std::uint32_t* const kept = kept_.data();
  const roi::PointXYZI* const placed_at = scratch_.data();
  const vlp16::Point* const batch = frame.points.data() + first;
  for (std::size_t k = 0; k < n; ++k) {
    const roi::PointXYZI& g = placed_at[kept[k]];
    const vlp16::Point& p = batch[kept[k]];
    x[k] = g.x;
    y[k] = g.y;
    z[k] = g.z;
    intensity[k] = p.intensity;
    ring[k] = p.ring;
    return_type[k] = static_cast<std::uint8_t>(p.return_type);
    time_offset_ns[k] = static_cast<std::int32_t>(p.time_offset_ns);
  }
  if (keep_indices_) {
    std::uint32_t* const index = grown(s.point_index);
    for (std::size_t k = 0; k < n; ++k)
      index[k] = static_cast<std::uint32_t>(first + kept[k]);
  }
  return pose::PoseStatus::kValid;
}

void SweepProcessor::end_sweep(const vlp16::Frame& frame, SweepSink& sink) {
  if (!in_sweep_) {
    start_sweep(frame);  // a frame of packets without points
    unfiltered_from_ = frame.points.size();
  }
  filter_points(frame, 1, sink);
  in_sweep_ = false;
  Sweep& s = sweep_;
  s.index = frame.index;
  s.end_ns = frame.end_time_ns;
  s.partial = frame.partial;
  s.return_mode = static_cast<std::uint8_t>(frame.return_mode);
  s.points_in = static_cast<std::uint32_t>(frame.points.size());
  s.lost_packets = frame.lost_packets;
  ++counters_.sweeps;
  counters_.points_in += frame.points.size();
  if (s.filtered) {
    ++counters_.sweeps_filtered;
    counters_.points_kept += s.size();
    counters_.points_truncated += s.truncated;
  } else {
    ++counters_.sweeps_without_pose;
    s.clear_points();
  }
  sink.on_sweep(s);
}

}  // namespace trajroi::daemon
