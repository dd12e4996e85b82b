#include "trajroi/pipeline/sweep_processor.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "processor_constants.hpp"
#include "trajroi/config/text_file.hpp"
#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/framing/little_endian.hpp"
#include "trajroi/pose_input_t.hpp"

namespace trajroi::pipeline {
namespace {

// The speed is the distance to the pose this long before, over the time. The pose must have
// been valid at every sweep start since then: right after a gap in the pose (a GNSS outage)
// the shorter baselines are tried, and in the first 0.1 s none (the speed is unknown).
constexpr std::array<std::int64_t, 3> kSpeedBaselines_ns{500'000'000, 200'000'000, 100'000'000};
constexpr double kMaxAdvancePerSweep_m = 10.0;  // projection search window (50 m/s at 5 Hz)
// Farther than this from the windowed projection, the robot is not where the window assumed
// (its pose jumped: relocalised, carried, a replay looping): the whole trajectory is searched.
constexpr double kReacquireDistance_m = 5.0;

double size_along(const DaemonConfig::Roi& r) {
  return r.shape == RoiShape::kCircular ? r.circle_diameter_m : r.rect_height_m;
}

}  // namespace

vlp16::Calibration load_calibration(const DaemonConfig::Lidar& lidar, const std::string& key) {
  const std::filesystem::path& file = lidar.calibration;
  const std::optional<vlp16::Model> model = vlp16::model_named(lidar.model);
  if (file.empty()) return vlp16::Calibration::for_model(model.value_or(vlp16::Model::kVlp16));
  vlp16::Calibration calibration;
  try {
    calibration = vlp16::parse_calibration_file(config::read_text_file(file), file.string());
  } catch (const std::exception& e) {
    throw config::ConfigError(key + ".calibration: " + e.what());  // names the file and its line
  }
  const vlp16::ModelSpec& s = vlp16::spec(model.value_or(vlp16::Model::kVlp16));
  if (!model && calibration.laser_count != s.lasers) {
    throw config::ConfigError(key + ".calibration " + file.string() + ": " + std::to_string(calibration.laser_count) +
                              " lasers: set " + key + ".model (vlp32c or hdl32e) for a 32-laser calibration");
  }
  if (calibration.laser_count != s.lasers) {
    throw config::ConfigError(key + ".calibration " + file.string() + ": " + std::to_string(calibration.laser_count) +
                              " lasers, but a " + std::string(s.name) + " (" + key + ".model " + lidar.model +
                              ") has " + std::to_string(s.lasers));
  }
  return calibration;
}

vlp16::StreamOptions stream_options(const DaemonConfig::Lidar& lidar) {
  vlp16::StreamOptions o;
  // A model named, or told from the packets; a calibration file without a model is a VLP-16's.
  const std::optional<vlp16::Model> model = vlp16::model_named(lidar.model);
  o.model = model.value_or(vlp16::Model::kVlp16);
  o.detect_model = !model && lidar.calibration.empty();
  o.decode.min_range_m = lidar.min_range_m;
  o.decode.max_range_m = lidar.max_range_m;
  o.cut_azimuth_deg = lidar.cut_azimuth_deg;
  return o;
}

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

// Routes the stream decoder's callbacks to the processor and on to the caller's sink.
class SweepProcessor::FrameAdapter final : public vlp16::FrameSink {
 public:
  FrameAdapter(SweepProcessor& processor, Lane& lane, SweepSink& sink)
      : processor_(processor), lane_(lane), sink_(sink) {}
  void on_points(const vlp16::Frame& frame, std::size_t first) override {
    processor_.add_points(lane_, frame, first, sink_);
  }
  void on_frame(const vlp16::Frame& frame) override { processor_.end_sweep(lane_, frame, sink_); }

 private:
  SweepProcessor& processor_;
  Lane& lane_;
  SweepSink& sink_;
};

namespace {

std::size_t chain_capacity(const DaemonConfig::Roi& r) {
  const double longest = r.look_ahead_m + r.max_speed_mps * r.look_ahead_per_mps_s;
  return static_cast<std::size_t>(longest / (r.spacing_ratio * size_along(r))) + 2;
}

std::uint32_t address_of(const std::string& text) {
  in_addr a{};
  return !text.empty() && inet_pton(AF_INET, text.c_str(), &a) == 1 ? ntohl(a.s_addr) : 0;
}

}  // namespace

SweepProcessor::Lane::Lane(const DaemonConfig& config, std::size_t i, const pose::PoseBuffer& poses)
    : lidar(config.all_lidars()[i]),
      index(i),
      decoder(load_calibration(lidar, config.lidar_key(i)), stream_options(lidar)),
      firing(
          poses, lidar.robot_from_lidar,
          config.pose_mode == PoseMode::kPerSweep ? std::numeric_limits<std::int64_t>::max() : vlp16::kFiringCycle_ns),
      chain(config.roi.shape,
            roi::ChainSize{config.roi.circle_diameter_m / 2.0, config.roi.rect_height_m, config.roi.rect_width_m},
            roi::ZLimits{config.roi.z_min_m, config.roi.z_max_m}),
      sender(address_of(lidar.sensor_address)) {}

SweepProcessor::SweepProcessor(const DaemonConfig& config, std::unique_ptr<ActiveTrajectory> trajectory)
    : config_(config),
      // A localization's pose is the robot origin's own: no lever arm.
      poses_(config.gate, config.pose_source == PoseSource::kLcm ? Eigen::Vector3d::Zero() : config.gnss_antenna_m,
             config.pose_capacity),
      pose_input_(pose::GlobalFrame::local_cartesian(config.origin), pose_input_config(config), poses_),
      active_(std::move(trajectory)) {
  if (!active_) throw std::invalid_argument("SweepProcessor: no trajectory");
  if (config_.pose_source == PoseSource::kFixed) poses_.hold(config_.fixed_pose);
  // Preallocate and touch: the largest chain the look-ahead can need, its grid, the sweep.
  const DaemonConfig::Roi& r = config_.roi;
  const double longest = r.look_ahead_m + r.max_speed_mps * r.look_ahead_per_mps_s;
  const std::size_t centres = chain_capacity(r);
  for (std::size_t i = 0; i < config_.all_lidars().size(); ++i) {
    auto lane = std::make_unique<Lane>(config_, i, poses_);
    lane->sweep.reserve(config_.buffers.max_points_per_sweep, centres, raw_points_capacity(config_));
    lane->chain.reserve(centres);
    lane->chain.place(active_->trajectory, 0.0, longest, r.spacing_ratio * size_along(r),
                      roi::ChainSize{r.circle_diameter_m / 2.0, r.rect_height_m, r.rect_width_m});
    lanes_.push_back(std::move(lane));
  }
  if (lanes_.size() > 1) {
    MergeOptions m;
    m.max_wait_ns = std::llround(config_.lidar_merge.max_wait_s * 1e9);
    m.silent_ns = std::llround(config_.lidar_merge.silent_s * 1e9);
    m.per_sensor = config_.lidar_merge.per_sensor;
    merger_ = std::make_unique<SweepMerger>(lanes_.size(), config_.buffers.max_points_per_sweep, centres,
                                            raw_points_capacity(config_), m);
  }
  scratch_.resize(kScratchPoints);  // used as [0, batch): never resized (value-initialising) after
  kept_.reserve(kScratchPoints);
}

SweepProcessor::~SweepProcessor() = default;

void SweepProcessor::make_resident() {
  for (const auto& lane : lanes_)
    lane->sweep.make_resident();
  if (merger_) merger_->make_resident();
}

int SweepProcessor::lane_for(const inputs::InputItem& item) const noexcept {
  if (lanes_.size() == 1) return 0;  // one LiDAR: its sockets take only its sender
  const auto address = static_cast<std::uint32_t>(item.sender >> 16);
  for (std::size_t i = 0; i < lanes_.size(); ++i) {
    const DaemonConfig::Lidar& l = lanes_[i]->lidar;
    const bool port =
        item.port == 0 || item.port == (item.stream == inputs::Stream::kLidarData ? l.data_port : l.position_port);
    if (port && (lanes_[i]->sender == 0 || lanes_[i]->sender == address)) return static_cast<int>(i);
  }
  return -1;
}

void SweepProcessor::process(const inputs::InputItem& item, SweepSink& sink, const vlp16::DecodedPacket* decoded) {
  now_ns_ = item.receive_ns;
  if (merger_) merger_->tick(item.receive_ns, sink);
  switch (item.stream) {
    case inputs::Stream::kLidarData:
    case inputs::Stream::kLidarPosition: {
      const int index = lane_for(item);
      if (index < 0) {
        ++counters_.lidar_unknown_sender;
        break;
      }
      Lane& lane = *lanes_[static_cast<std::size_t>(index)];
      if (item.stream == inputs::Stream::kLidarPosition) {
        lane.decoder.on_position_packet(item.bytes);
        break;
      }
      FrameAdapter adapter(*this, lane, sink);
      lane.decoder.on_data_packet(item.bytes, item.receive_ns, adapter, decoded);
      break;
    }
    case inputs::Stream::kGnss:
      pose_input_.gnss_bytes(item.bytes, item.receive_ns);
      break;
    case inputs::Stream::kImu:
      pose_input_.imu_bytes(item.bytes, item.receive_ns);
      break;
    case inputs::Stream::kPose:
      pose_message(item.bytes);  // the message carries its own time
      break;
  }
}

double SweepProcessor::host_minus_gnss_utc_s() const noexcept {
  const auto& gnss = pose_input_.gnss_utc();
  if (!gnss || !host_utc_offset_ns_) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(gnss->host_ns + *host_utc_offset_ns_ - gnss->utc_ns) * 1e-9;
}

double SweepProcessor::gnss_time_accuracy_s() const noexcept {
  const auto& gnss = pose_input_.gnss_utc();
  return gnss ? static_cast<double>(gnss->accuracy_ns) * 1e-9 : std::numeric_limits<double>::quiet_NaN();
}

void SweepProcessor::pose_message(std::span<const std::uint8_t> bytes) {
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
  for (const auto& lane : lanes_) {
    FrameAdapter adapter(*this, *lane, sink);
    lane->decoder.flush(adapter);
  }
  if (merger_) merger_->flush(sink);
}

void SweepProcessor::keep_point_indices() {
  keep_indices_ = true;
  for (const auto& lane : lanes_)
    lane->sweep.point_index.reserve(config_.buffers.max_points_per_sweep);
}

void SweepProcessor::offer_trajectory(std::unique_ptr<ActiveTrajectory> trajectory) {
  if (pending_) retired_ = std::move(pending_);
  pending_ = std::move(trajectory);
}

std::unique_ptr<ActiveTrajectory> SweepProcessor::take_retired() noexcept {
  return std::move(retired_);
}

void SweepProcessor::start_sweep(Lane& lane, const vlp16::Frame& frame) {
  lane.in_sweep = true;
  if (pending_) {
    retired_ = std::move(active_);
    active_ = std::move(pending_);
    have_hint_ = false;
    ++counters_.trajectory_swaps;
  }
  Sweep& s = lane.sweep;
  s.clear_points();
  s.centres.clear();
  s.truncated = 0;
  s.start_ns = frame.start_time_ns;
  if (frame.start_utc_ns) {
    s.start_utc_ns = *frame.start_utc_ns;
    s.time_source = "vlp16_pps";
    if (host_utc_offset_ns_) {
      lane.host_minus_lidar_utc_s =
          static_cast<double>(frame.start_time_ns + *host_utc_offset_ns_ - *frame.start_utc_ns) * 1e-9;
    }
  } else if (host_utc_offset_ns_) {
    s.start_utc_ns = frame.start_time_ns + *host_utc_offset_ns_;
    s.time_source = "host";
  } else {
    s.start_utc_ns = 0;
    s.time_source = "none";
  }
  s.pose_t_ns = frame.start_time_ns;
  s.trajectory_id = active_->id;
  s.shape = config_.roi.shape;
  s.speed_mps = 0.0;
  const pose::GnssFix* fix = poses_.newest_fix();
  s.fix = fix != nullptr ? fix->quality : pose::FixQuality{};
  s.fix_t_ns = fix != nullptr ? fix->t_ns : 0;
  lane.firing.reset();

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
  s.sensor = PublishedPose::from(s.robot.isometry() * lane.lidar.robot_from_lidar);
  lane.sweep_sensor_pose = s.sensor.isometry();
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
  place_chain(lane, position);
}

void SweepProcessor::place_chain(Lane& lane, const Eigen::Vector2d& position) {
  const DaemonConfig::Roi& r = config_.roi;
  Sweep& s = lane.sweep;
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
  } else {
    s.radius_m = 0.0;
    s.height_m = r.rect_height_m;
    s.width_m = r.rect_width_m + grow;
    s.spacing_m = roi::spacing_from_ratio(r.spacing_ratio, r.rect_height_m);
  }
  lane.chain.place(trajectory, s.start_s_m, s.look_ahead_m, s.spacing_m,
                   roi::ChainSize{s.radius_m, s.height_m, s.width_m});
  s.centres.assign(lane.chain.centres().begin(), lane.chain.centres().end());
}

}  // namespace trajroi::pipeline
