#include "trajroi/sim/simulator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "trajroi/pose/geodetic.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/transform.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vlp16/decoder.hpp"
#include "trajroi/vlp16/encoder.hpp"
#include "trajroi/vlp16/packet_source.hpp"
#include "trajroi/vn100/decoder.hpp"

namespace trajroi::sim {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr std::int64_t kSecond_ns = 1'000'000'000;
constexpr std::int64_t kHour_ns = vlp16::kHour_us * 1000;
// GPS time = UTC + 18 s (leap seconds since 2017-01-01); the GPS epoch 1980-01-06 in UTC.
constexpr std::int64_t kGpsMinusUtc_ns = 18 * kSecond_ns;
constexpr std::int64_t kGpsEpochUtc_ns = 315'964'800 * kSecond_ns;
constexpr std::int64_t kWeek_ns = 604'800 * kSecond_ns;
constexpr double kGravity_mps2 = 9.80665;
constexpr double kMpsToKnots = 3600.0 / 1852.0;
// VN-100 output: TimeStartup, YawPitchRoll, AngularRate, Accel of the Common group.
constexpr std::array<std::uint16_t, 8> kImuFields{0x0001 | 0x0008 | 0x0020 | 0x0100, 0, 0, 0, 0, 0, 0, 0};
// Position packets: the sensor sends its RMC this long after the PPS second it names.
constexpr std::int64_t kPositionDelay_ns = 200'000'000;

std::int64_t bytes_time_ns(std::size_t bytes, double baud) {
  return static_cast<std::int64_t>(std::llround(static_cast<double>(bytes) * 10.0 / baud * 1e9));
}

// Bearing (degrees clockwise from true north, [0, 360)) of a global-frame yaw at `where`.
double true_bearing_deg(const pose::GlobalFrame& frame, const pose::Geodetic& where, double yaw_rad) {
  const Eigen::Vector3d forward_local =
      frame.global_from_local_enu(where).transpose() * Eigen::Vector3d(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  const double bearing = std::atan2(forward_local.x(), forward_local.y()) * kRadToDeg;
  return bearing < 0.0 ? bearing + 360.0 : bearing;
}

double wrap_deg(double a) {
  a = std::fmod(a + 180.0, 360.0);
  return (a < 0.0 ? a + 360.0 : a) - 180.0;
}

Eigen::Isometry3d robot_pose(const RobotState& s) {
  return roi::pose_from_xy_yaw(s.position_m.x(), s.position_m.y(), s.yaw_rad);
}

}  // namespace

struct Simulator::Impl {
  explicit Impl(const Scenario& s)
      : scenario(s),
        path(s.path),
        motion(path, s.robot),
        world(s.world),
        csv(path.trajectory_csv("trajectory of scenario '" + s.name + "'")),
        trajectory(roi::parse_trajectory_csv(csv, "trajectory.csv")),
        frame(pose::GlobalFrame::local_cartesian(s.origin)),
        corridor(trajectory, 0.0, trajectory.length_m(), s.evaluation.corridor_width_m) {
    corridor_grid.build(corridor);
  }

  void run_lidar(SimulationSink& sink, SimulationStats& stats, const std::function<void(double)>& progress) const;
  void run_gnss(SimulationSink& sink, SimulationStats& stats) const;
  void run_imu(SimulationSink& sink, SimulationStats& stats) const;
  void position_packet(SimulationSink& sink, std::int64_t pps_utc_ns) const;

  Scenario scenario;
  Path path;
  Motion motion;
  World world;
  std::string csv;
  roi::Trajectory trajectory;
  pose::GlobalFrame frame;
  vlp16::Calibration calibration = vlp16::Calibration::vlp16_default();
  Eigen::Isometry3d robot_from_lidar = scenario.robot.lidar.robot_from_sensor();
  roi::CorridorRoiSet corridor;
  roi::GridFilter<roi::CorridorRoiSet> corridor_grid;
};

Simulator::Simulator(const Scenario& scenario) : impl_(std::make_unique<Impl>(scenario)) {}
Simulator::~Simulator() = default;
const Scenario& Simulator::scenario() const noexcept {
  return impl_->scenario;
}
const Path& Simulator::path() const noexcept {
  return impl_->path;
}
const std::string& Simulator::trajectory_csv() const noexcept {
  return impl_->csv;
}
const roi::Trajectory& Simulator::trajectory() const noexcept {
  return impl_->trajectory;
}

SimulationStats Simulator::run(SimulationSink& sink, const std::function<void(double)>& progress) const {
  SimulationStats stats;
  stats.duration_ns = impl_->motion.duration_ns();
  impl_->run_lidar(sink, stats, progress);
  impl_->run_gnss(sink, stats);
  impl_->run_imu(sink, stats);
  return stats;
}

void Simulator::Impl::position_packet(SimulationSink& sink, std::int64_t pps_utc_ns) const {
  const std::int64_t send_ns = pps_utc_ns + kPositionDelay_ns;
  const RobotState state = motion.at(pps_utc_ns - scenario.start_utc_ns);
  const Eigen::Vector3d antenna = robot_pose(state) * scenario.robot.gnss_antenna_m;
  const pose::Geodetic where = frame.to_geodetic(antenna);
  const vlp16::Rmc rmc{pps_utc_ns, true, where.lat_deg, where.lon_deg};
  const std::string sentence =
      vlp16::format_rmc(rmc, state.speed_mps * kMpsToKnots, true_bearing_deg(frame, where, state.yaw_rad));
  std::array<std::uint8_t, vlp16::kPositionPacketBytes> bytes{};
  vlp16::encode_position_packet(static_cast<std::uint32_t>((send_ns % kHour_ns) / 1000), vlp16::PpsStatus::kLocked,
                                sentence, bytes);
  sink.lidar_datagram(send_ns, vlp16::kPositionPort, bytes);
}

void Simulator::Impl::run_lidar(SimulationSink& sink, SimulationStats& stats,
                                const std::function<void(double)>& progress) const {
  const LidarSpec& lidar = scenario.lidar;
  const std::size_t blocks_per_packet = vlp16::firing_blocks_per_packet(lidar.return_mode);
  const std::int64_t period_ns = static_cast<std::int64_t>(blocks_per_packet) * vlp16::kBlockDuration_ns;
  const double cdeg_per_ns = lidar.rpm * 36'000.0 / 60.0 / 1e9;
  const std::int64_t duration = motion.duration_ns();

  struct LaserRay {
    double cos_vert, sin_vert, vert_offset_m;
  };
  std::array<LaserRay, vlp16::kLasers> lasers{};
  for (std::size_t l = 0; l < vlp16::kLasers; ++l) {
    const vlp16::LaserCalibration& c = calibration.lasers[l];
    lasers[l] = {std::cos(c.vert_angle_rad), std::sin(c.vert_angle_rad), c.vert_offset_m};
  }

  std::mt19937_64 rng(scenario.seed * 3 + 0);
  std::normal_distribution<double> range_noise(0.0, 1.0);
  std::vector<vlp16::FiringBlock> blocks(blocks_per_packet);
  std::array<std::uint8_t, vlp16::kDataPacketBytes> packet{};
  std::vector<roi::PointXYZd> measured;
  measured.reserve(vlp16::kBlocks * vlp16::kChannelsPerBlock);
  roi::IndexVector kept;
  kept.reserve(measured.capacity());
  std::vector<std::uint8_t> labels;
  std::vector<std::uint16_t> azimuth(blocks_per_packet);

  std::int64_t next_pps = (scenario.start_utc_ns + kSecond_ns - 1) / kSecond_ns * kSecond_ns;
  for (std::int64_t n = 0;; ++n) {
    const std::int64_t t_first = n * period_ns;
    if (t_first >= duration) break;
    const std::int64_t receive_ns = scenario.start_utc_ns + t_first + period_ns;
    while (next_pps + kPositionDelay_ns <= receive_ns && next_pps - scenario.start_utc_ns < duration) {
      position_packet(sink, next_pps);
      ++stats.position_packets;
      next_pps += kSecond_ns;
    }
    for (std::size_t b = 0; b < blocks_per_packet; ++b) {
      const double a =
          lidar.start_azimuth_deg * 100.0 +
          static_cast<double>(t_first + static_cast<std::int64_t>(b) * vlp16::kBlockDuration_ns) * cdeg_per_ns;
      azimuth[b] = static_cast<std::uint16_t>(std::llround(a) % vlp16::kAzimuthLimit);
    }
    measured.clear();
    for (std::size_t b = 0; b < blocks_per_packet; ++b) {
      // The decoder's interpolation between block azimuths, so every ray leaves at the
      // azimuth its point will be decoded at.
      const auto gap = static_cast<double>(b + 1 < blocks_per_packet ? vlp16::azimuth_gap(azimuth[b], azimuth[b + 1])
                                                                     : vlp16::azimuth_gap(azimuth[b - 1], azimuth[b]));
      vlp16::FiringBlock& block = blocks[b];
      block.azimuth_cdeg = azimuth[b];
      for (std::size_t seq = 0; seq < vlp16::kFiringsPerBlock; ++seq) {
        const std::int64_t t_seq = t_first + static_cast<std::int64_t>(b) * vlp16::kBlockDuration_ns +
                                   static_cast<std::int64_t>(seq) * vlp16::kFiringCycle_ns;
        const RobotState at_seq = motion.at(t_seq);
        sink.firing_pose({scenario.start_utc_ns + t_seq, at_seq.position_m.x(), at_seq.position_m.y(), at_seq.yaw_rad});
        for (std::size_t l = 0; l < vlp16::kLasers; ++l) {
          const std::size_t channel = seq * vlp16::kLasers + l;
          const std::int64_t t = t_seq + static_cast<std::int64_t>(l) * vlp16::kLaserPeriod_ns;
          const double theta =
              (static_cast<double>(azimuth[b]) + gap * vlp16::azimuth_fraction(channel)) * (kDegToRad / 100.0);
          const LaserRay& laser = lasers[l];
          const double ct = std::cos(theta), st = std::sin(theta);
          // Sensor frame (the decoder's model): p = R d + o.
          const Eigen::Vector3d d_s(laser.cos_vert * ct, -laser.cos_vert * st, laser.sin_vert);
          const Eigen::Vector3d o_s(-laser.vert_offset_m * laser.sin_vert * ct,
                                    laser.vert_offset_m * laser.sin_vert * st, laser.vert_offset_m * laser.cos_vert);
          const Eigen::Isometry3d global_from_lidar = robot_pose(motion.at(t)) * robot_from_lidar;
          const Eigen::Vector3d o = global_from_lidar * o_s;
          const Eigen::Vector3d d = global_from_lidar.linear() * d_s;
          ++stats.rays;
          vlp16::Echo echo;
          if (const auto hit = world.cast(o, d, lidar.max_range_m + 5.0 * lidar.range_noise_m)) {
            const double range =
                hit->range_m + (lidar.range_noise_m > 0.0 ? lidar.range_noise_m * range_noise(rng) : 0.0);
            const long long raw = std::llround(range / vlp16::kDistanceUnit_m);
            if (range >= lidar.min_range_m && range <= lidar.max_range_m && raw >= 1 && raw <= 65535) {
              echo = {static_cast<std::uint16_t>(raw), hit->reflectivity};
              const Eigen::Vector3d p = o + (static_cast<double>(raw) * vlp16::kDistanceUnit_m) * d;
              measured.push_back({p.x(), p.y(), p.z()});
            }
          }
          // One surface per ray: the strongest return is the last one (in dual mode the
          // decoder reports it once).
          block.strongest[channel] = echo;
          block.last[channel] = echo;
        }
      }
    }
    const auto toh_us = static_cast<std::uint32_t>(((scenario.start_utc_ns + t_first) % kHour_ns) / 1000);
    vlp16::encode_data_packet({lidar.return_mode, vlp16::kProductVlp16, toh_us}, blocks, packet);
    sink.lidar_datagram(receive_ns, vlp16::kDataPort, packet);
    ++stats.data_packets;

    corridor_grid.filter(std::span<const roi::PointXYZd>(measured), kept);
    labels.assign(measured.size(), 0);
    for (const std::uint32_t i : kept)
      labels[i] = 1;
    sink.point_labels(labels);
    stats.points += measured.size();
    stats.points_in_corridor += kept.size();
    if (progress && n % 2000 == 0) progress(static_cast<double>(t_first) / static_cast<double>(duration));
  }
}

void Simulator::Impl::run_gnss(SimulationSink& sink, SimulationStats& stats) const {
  const GnssSpec& g = scenario.gnss;
  const auto step_ns = static_cast<std::int64_t>(std::llround(1e9 / g.rate_hz));
  const std::int64_t gps_start = scenario.start_utc_ns - kGpsEpochUtc_ns + kGpsMinusUtc_ns;
  std::int64_t gps = (gps_start + step_ns - 1) / step_ns * step_ns;  // epochs on the GPS second grid
  const std::int64_t duration = motion.duration_ns();
  std::mt19937_64 rng(scenario.seed * 3 + 1);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double phi = std::exp(-static_cast<double>(step_ns) * 1e-9 / g.correlation_s);
  const double drive = std::sqrt(1.0 - phi * phi);
  Eigen::Vector3d error(g.noise_h_m * unit(rng), g.noise_h_m * unit(rng), g.noise_v_m * unit(rng));
  double last_head_mot_deg = 0.0;

  for (;; gps += step_ns) {
    const std::int64_t utc = gps + kGpsEpochUtc_ns - kGpsMinusUtc_ns;
    const std::int64_t t = utc - scenario.start_utc_ns;
    if (t >= duration) break;
    error = phi * error +
            drive * Eigen::Vector3d(g.noise_h_m * unit(rng), g.noise_h_m * unit(rng), g.noise_v_m * unit(rng));
    const GnssFault* fault = nullptr;
    for (const GnssFault& f : g.faults) {
      if (static_cast<double>(t) * 1e-9 >= f.from_s && static_cast<double>(t) * 1e-9 < f.to_s) {
        fault = &f;
        break;
      }
    }
    Eigen::Vector3d extra = Eigen::Vector3d::Zero();
    if (fault != nullptr) extra = fault->noise_m * Eigen::Vector3d(unit(rng), unit(rng), 1.5 * unit(rng));
    const RobotState state = motion.at(t);
    const Eigen::Vector3d antenna = robot_pose(state) * scenario.robot.gnss_antenna_m + error + extra;
    const pose::Geodetic where = frame.to_geodetic(antenna);
    const bool lost = fault != nullptr && fault->kind == GnssFault::Kind::kLost;
    const double h_acc = fault != nullptr ? fault->h_acc_m : g.h_acc_m;

    ublox::NavPvt pvt;
    pvt.itow_ms = static_cast<std::uint32_t>((gps % kWeek_ns) / 1'000'000);
    {
      namespace c = std::chrono;
      const c::sys_time<c::nanoseconds> when{c::nanoseconds{utc}};
      const auto second = c::floor<c::seconds>(when);
      const auto day = c::floor<c::days>(second);
      const c::year_month_day ymd{day};
      const c::hh_mm_ss hms{second - day};
      pvt.year = static_cast<std::uint16_t>(int{ymd.year()});
      pvt.month = static_cast<std::uint8_t>(unsigned{ymd.month()});
      pvt.day = static_cast<std::uint8_t>(unsigned{ymd.day()});
      pvt.hour = static_cast<std::uint8_t>(hms.hours().count());
      pvt.minute = static_cast<std::uint8_t>(hms.minutes().count());
      pvt.second = static_cast<std::uint8_t>(hms.seconds().count());
      pvt.nano_ns = static_cast<std::int32_t>((when - second).count());
    }
    pvt.valid_date = pvt.valid_time = pvt.fully_resolved = true;
    pvt.time_accuracy_ns = 20;
    pvt.fix_type_raw = lost ? 0 : 3;
    pvt.gnss_fix_ok = !lost;
    pvt.diff_soln = fault == nullptr || fault->kind == GnssFault::Kind::kFloat;
    pvt.carr_soln = fault == nullptr                         ? ublox::CarrierSolution::kFixed
                    : fault->kind == GnssFault::Kind::kFloat ? ublox::CarrierSolution::kFloat
                                                             : ublox::CarrierSolution::kNone;
    pvt.num_sv = lost ? 0 : 18;
    pvt.invalid_llh = lost;
    const std::int64_t lat_e9 = lost ? 0 : std::llround(where.lat_deg * 1e9);
    const std::int64_t lon_e9 = lost ? 0 : std::llround(where.lon_deg * 1e9);
    const std::int64_t height_e4 = lost ? 0 : std::llround(where.height_m * 1e4);
    pvt.lat_e7 = static_cast<std::int32_t>(std::llround(static_cast<double>(lat_e9) / 100.0));
    pvt.lon_e7 = static_cast<std::int32_t>(std::llround(static_cast<double>(lon_e9) / 100.0));
    pvt.height_mm = static_cast<std::int32_t>(std::llround(static_cast<double>(height_e4) / 10.0));
    pvt.hmsl_mm = pvt.height_mm;  // the simulated world's geoid coincides with the ellipsoid
    pvt.h_acc_mm = static_cast<std::uint32_t>(std::llround(h_acc * 1000.0));
    pvt.v_acc_mm = static_cast<std::uint32_t>(std::llround(h_acc * 1500.0));
    const double bearing = true_bearing_deg(frame, where, state.yaw_rad);
    const double speed = lost ? 0.0 : state.speed_mps;
    pvt.vel_n_mmps = static_cast<std::int32_t>(std::llround(speed * std::cos(bearing * kDegToRad) * 1000.0));
    pvt.vel_e_mmps = static_cast<std::int32_t>(std::llround(speed * std::sin(bearing * kDegToRad) * 1000.0));
    pvt.ground_speed_mmps = static_cast<std::int32_t>(std::llround(speed * 1000.0));
    if (speed > 0.0) last_head_mot_deg = bearing;
    pvt.head_mot_e5deg = static_cast<std::int32_t>(std::llround(last_head_mot_deg * 1e5)) % 36'000'000;
    pvt.speed_acc_mmps = 20;
    pvt.head_acc_e5deg = speed > 0.0 ? 50'000 : 18'000'000;
    pvt.pdop_e2 = lost ? 9999 : 120;
    pvt.has_head_veh = true;

    ublox::NavHpposllh hp;
    hp.itow_ms = pvt.itow_ms;
    hp.invalid_llh = lost;
    hp.lat_e7 = static_cast<std::int32_t>(lat_e9 / 100);
    hp.lat_hp_e9 = static_cast<std::int8_t>(lat_e9 % 100);
    hp.lon_e7 = static_cast<std::int32_t>(lon_e9 / 100);
    hp.lon_hp_e9 = static_cast<std::int8_t>(lon_e9 % 100);
    hp.height_mm = static_cast<std::int32_t>(height_e4 / 10);
    hp.height_hp_e4m = static_cast<std::int8_t>(height_e4 % 10);
    hp.hmsl_mm = hp.height_mm;
    hp.hmsl_hp_e4m = hp.height_hp_e4m;
    hp.h_acc_e4m = static_cast<std::uint32_t>(std::llround(h_acc * 1e4));
    hp.v_acc_e4m = static_cast<std::uint32_t>(std::llround(h_acc * 1.5e4));

    const std::vector<std::uint8_t> hp_bytes = ublox::encode_nav_hpposllh(hp);
    const std::vector<std::uint8_t> pvt_bytes = ublox::encode_nav_pvt(pvt);
    const std::int64_t first_byte = utc + static_cast<std::int64_t>(std::llround(g.latency_s * 1e9));
    sink.gnss_chunk(first_byte + bytes_time_ns(hp_bytes.size(), g.baud), hp_bytes);
    sink.gnss_chunk(first_byte + bytes_time_ns(hp_bytes.size() + pvt_bytes.size(), g.baud), pvt_bytes);
    ++stats.gnss_epochs;
  }
}

void Simulator::Impl::run_imu(SimulationSink& sink, SimulationStats& stats) const {
  const ImuSpec& imu = scenario.imu;
  const std::int64_t period_ns = static_cast<std::int64_t>(imu.rate_divisor) * 1'250'000;  // 800 Hz base
  const std::int64_t boot_utc_ns = scenario.start_utc_ns - 60 * kSecond_ns;
  const std::int64_t duration = motion.duration_ns();
  std::mt19937_64 rng(scenario.seed * 3 + 2);
  std::normal_distribution<double> unit(0.0, 1.0);
  const auto noisy = [&](double value, double sigma) {
    return static_cast<float>(sigma > 0.0 ? value + sigma * unit(rng) : value);
  };

  for (std::int64_t t = 0; t < duration; t += period_ns) {
    const RobotState state = motion.at(t);
    const pose::Geodetic where = frame.to_geodetic(Eigen::Vector3d(state.position_m.x(), state.position_m.y(), 0.0));
    const double magnetic_yaw =
        true_bearing_deg(frame, where, state.yaw_rad) - imu.magnetic_declination_deg + imu.heading_bias_deg;
    vn100::Sample sample;
    sample.set(vn100::Field::kTimeStartup);
    sample.set(vn100::Field::kYawPitchRoll);
    sample.set(vn100::Field::kAngularRate);
    sample.set(vn100::Field::kAccel);
    sample.time_startup_ns = static_cast<std::uint64_t>(scenario.start_utc_ns + t - boot_utc_ns);
    sample.ypr_deg = {static_cast<float>(wrap_deg(static_cast<double>(noisy(magnetic_yaw, imu.angle_noise_deg)))),
                      noisy(0.0, imu.angle_noise_deg), noisy(0.0, imu.angle_noise_deg)};
    // Body FRD: a left turn (counter-clockwise, ω > 0) is a negative rate about z-down, and
    // its centripetal acceleration v·ω points left (−y); at rest the specific force is −g.
    sample.angular_rate_rps = {noisy(0.0, imu.gyro_noise_rps), noisy(0.0, imu.gyro_noise_rps),
                               noisy(-state.yaw_rate_rps, imu.gyro_noise_rps)};
    sample.accel_mps2 = {noisy(0.0, imu.accel_noise_mps2),
                         noisy(-state.speed_mps * state.yaw_rate_rps, imu.accel_noise_mps2),
                         noisy(-kGravity_mps2, imu.accel_noise_mps2)};
    const std::vector<std::uint8_t> bytes = vn100::encode(sample, kImuFields);
    sink.imu_chunk(scenario.start_utc_ns + t + static_cast<std::int64_t>(std::llround(imu.latency_s * 1e9)) +
                       bytes_time_ns(bytes.size(), imu.baud),
                   bytes);
    ++stats.imu_frames;
  }
}

}  // namespace trajroi::sim
