// The simulator against the VLP-16 manual and analytic geometry: a wall at a known distance
// gives the right ranges at the right times, motion during a sweep shows in the data, and
// the serial streams carry the true pose. Then a whole run written to a folder decodes, with
// the project's own drivers, back to the simulator's truth.
#include "trajroi/sim/simulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <vector>

#include "trajroi/eval/scenario_eval.hpp"
#include "trajroi/sim/run_folder.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vlp16/decoder.hpp"
#include "trajroi/vlp16/packet_source.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// A robot at the origin facing east (+x) towards a wall whose face is at x = 10; the lidar
// 1 m up at the robot's origin; no noise.
Scenario wall_scenario(double speed_mps, double wait_before_s) {
  Scenario s = parse_scenario(R"(name: wall
start_utc: 2024-05-14T09:59:59.5Z
origin: {lat_deg: 36.0, lon_deg: 127.0, height_m: 50}
world:
  boxes:
    - {name: wall, centre: [10.1, 0], size: [0.2, 60], height: 20, reflectivity: 90}
trajectory: {start: [0, 0], heading_deg: 0, segments: [{line: 2}]}
robot: {speed_mps: 1, wait_before_s: 1, wait_after_s: 0, lidar_mount: {xyz: [0, 0, 1]}, gnss_antenna: [0, 0, 1.5]}
lidar: {rpm: 600, max_range_m: 100, range_noise_m: 0}
)",
                              "wall.yaml");
  s.robot.speed_mps = speed_mps;
  s.robot.wait_before_s = wait_before_s;
  return s;
}

struct Captured {
  struct Datagram {
    std::int64_t t_ns;
    std::uint16_t port;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Datagram> lidar;
  std::vector<std::pair<std::int64_t, std::vector<std::uint8_t>>> gnss, imu;
  std::vector<TruePose> poses;
  std::vector<std::uint8_t> labels;
};

class MemorySink final : public SimulationSink {
 public:
  Captured c;
  void lidar_datagram(std::int64_t t, std::uint16_t port, std::span<const std::uint8_t> p) override {
    c.lidar.push_back({t, port, {p.begin(), p.end()}});
  }
  void gnss_chunk(std::int64_t t, std::span<const std::uint8_t> b) override {
    c.gnss.emplace_back(t, std::vector(b.begin(), b.end()));
  }
  void imu_chunk(std::int64_t t, std::span<const std::uint8_t> b) override {
    c.imu.emplace_back(t, std::vector(b.begin(), b.end()));
  }
  void firing_pose(const TruePose& p) override { c.poses.push_back(p); }
  void point_labels(std::span<const std::uint8_t> l) override { c.labels.insert(c.labels.end(), l.begin(), l.end()); }
};

TEST(Simulator, WallAtKnownDistanceGivesTheManualsRangesAndTimes) {
  const Scenario s = wall_scenario(1.0, 1.0);
  const Simulator sim(s);
  MemorySink sink;
  const SimulationStats stats = sim.run(sink);
  EXPECT_EQ(stats.duration_ns, 3'000'000'000);  // 1 s waiting + 2 m at 1 m/s

  // Packets every 12 × 110.592 µs, each record at the end of its last firing; timestamps
  // µs past the hour (this run crosses 10:00:00, where they wrap).
  const vlp16::PacketDecoder decoder(vlp16::Calibration::vlp16_default());
  const vlp16::Calibration cal = vlp16::Calibration::vlp16_default();
  std::int64_t packet = 0;
  std::size_t wall_points = 0;
  std::vector<vlp16::Point> points;
  for (const auto& d : sink.c.lidar) {
    if (d.port != vlp16::kDataPort) continue;
    const std::int64_t first_firing = s.start_utc_ns + packet * 1'327'104;
    ASSERT_EQ(d.t_ns, first_firing + 1'327'104);
    ASSERT_EQ(vlp16::validate_data_packet(d.bytes), vlp16::PacketError::kNone);
    ASSERT_EQ(vlp16::timestamp_us(d.bytes), static_cast<std::uint32_t>((first_firing % 3'600'000'000'000) / 1000));
    points.clear();
    decoder.decode(d.bytes, points);
    for (const vlp16::Point& p : points) {
      // Where the robot was when this laser fired (it starts moving after 1 s).
      const double t_s = static_cast<double>(first_firing - s.start_utc_ns + p.time_offset_ns) * 1e-9;
      const double robot_x = std::clamp(t_s - 1.0, 0.0, 2.0);
      const double theta = -static_cast<double>(p.azimuth_deg) * kPi / 180.0;  // the VLP-16 azimuth turns clockwise
      const double omega = cal.lasers[p.laser].vert_angle_rad, v = cal.lasers[p.laser].vert_offset_m;
      // The manual's geometry from the sensor (1 m up): p = R d + v (−sin ω cos θ, …, cos ω).
      const double dx = std::cos(omega) * std::cos(theta);
      const double ox = -v * std::sin(omega) * std::cos(theta);
      const double oz = 1.0 + v * std::cos(omega);
      const double dz = std::sin(omega);
      if (dx <= 0.0) continue;
      const double range_to_wall = (10.0 - robot_x - ox) / dx;
      const double z_at_wall = oz + range_to_wall * dz;
      const double range_to_ground = dz < 0.0 ? -oz / dz : 1e9;
      const double y_at_wall = range_to_wall * std::cos(omega) * std::sin(theta);
      if (range_to_ground < range_to_wall || z_at_wall > 20.0 || std::abs(y_at_wall) > 29.95) continue;
      // 2 mm range units; 1 µm of time rounding in the timestamps is far below that.
      ASSERT_NEAR(static_cast<double>(p.distance_m), range_to_wall, 0.0011)
          << "packet " << packet << " laser " << int(p.laser);
      ASSERT_EQ(p.intensity, 90);
      ++wall_points;
    }
    ++packet;
  }
  EXPECT_EQ(packet, stats.data_packets);
  EXPECT_EQ(stats.data_packets, 2261u);  // ceil(3 s / 1327.104 µs)
  EXPECT_GT(wall_points, 10'000u);
  EXPECT_EQ(sink.c.labels.size(), stats.points);

  // One true pose per firing sequence, 55.296 µs apart.
  ASSERT_EQ(sink.c.poses.size(), stats.data_packets * 24);
  EXPECT_EQ(sink.c.poses[1].t_ns - sink.c.poses[0].t_ns, 55'296);
  EXPECT_NEAR(sink.c.poses.back().x_m, 2.0, 1e-3);

  // Position packets once per second (the sensor's $GPRMC), at 09:59:60 − 0.5 s, 10:00:00, …
  std::size_t position = 0;
  for (const auto& d : sink.c.lidar) {
    if (d.port != vlp16::kPositionPort) continue;
    vlp16::PositionPacket pp;
    ASSERT_TRUE(vlp16::parse_position_packet(d.bytes, pp));
    ASSERT_EQ(pp.nmea, vlp16::NmeaError::kNone);
    EXPECT_EQ(pp.rmc.utc_ns % 1'000'000'000, 0);
    EXPECT_EQ(d.t_ns - pp.rmc.utc_ns, 200'000'000);
    ++position;
  }
  EXPECT_EQ(position, stats.position_packets);
  EXPECT_EQ(position, 3u);
}

TEST(Simulator, SerialStreamsCarryTheTruePose) {
  const Scenario s = wall_scenario(1.0, 1.0);
  const Simulator sim(s);
  MemorySink sink;
  const SimulationStats stats = sim.run(sink);
  // GNSS: 8 Hz on the GPS time grid, HPPOSLLH then PVT, both decoding to the antenna position.
  ublox::Framer framer;
  std::size_t pvts = 0;
  std::int64_t last_pvt_t = 0;
  for (const auto& chunk : sink.c.gnss) {
    // Named copies: clang 14 cannot capture structured bindings in the lambda.
    const auto t = chunk.first;
    const auto& bytes = chunk.second;
    framer.feed(bytes, [&](const ublox::Message& m) {
      if (m.msg_id != ublox::kIdNavPvt) return;
      const auto d = ublox::decode_nav_pvt(m.payload);
      ASSERT_TRUE(d.ok());
      EXPECT_TRUE(d.value.utc_valid());
      EXPECT_EQ(d.value.itow_ms % 125, 0u);
      EXPECT_EQ(d.value.fix_type_raw, 3);
      EXPECT_EQ(d.value.carr_soln, ublox::CarrierSolution::kFixed);
      // Received latency + (44 + 100) bytes at 115200 baud after the epoch.
      EXPECT_EQ(t - d.value.utc_ns(), 20'000'000 + std::llround(144 * 10 / 115200.0 * 1e9));
      if (last_pvt_t != 0) {
        EXPECT_EQ(t - last_pvt_t, 125'000'000);
      }
      last_pvt_t = t;
      ++pvts;
    });
  }
  EXPECT_EQ(pvts, stats.gnss_epochs);
  EXPECT_EQ(framer.counters().checksum_errors, 0u);
  // IMU: 800/13 Hz, yaw = the true bearing (east = 90°), level, TimeStartup spaced 16.25 ms.
  vn100::Framer vn;
  std::size_t frames = 0;
  std::uint64_t last_startup = 0;
  for (const auto& [t, bytes] : sink.c.imu) {
    vn.feed(bytes, [&](std::span<const std::uint8_t> frame) {
      vn100::Sample sample;
      ASSERT_TRUE(vn100::decode(frame, sample));
      EXPECT_NEAR(static_cast<double>(sample.ypr_deg[0]), 90.0, 1e-4);
      EXPECT_EQ(sample.ypr_deg[1], 0.0f);
      EXPECT_NEAR(static_cast<double>(sample.accel_mps2[2]), -9.80665, 1e-5);
      if (last_startup != 0) {
        EXPECT_EQ(sample.time_startup_ns - last_startup, 16'250'000u);
      }
      last_startup = sample.time_startup_ns;
      ++frames;
    });
  }
  EXPECT_EQ(frames, stats.imu_frames);
  EXPECT_EQ(frames, 185u);  // ceil(3 s / 16.25 ms)
}

// A short drive with a curve and noisy GNSS/IMU, written to a folder and read back.
const char* kDriveScenario = R"(name: drive
seed: 7
start_utc: 2024-05-14T09:00:00Z
origin: {lat_deg: 36.3721, lon_deg: 127.3604, height_m: 60}
world:
  boxes:
    - {name: wall_n, centre: [0, 20], size: [60, 0.3], height: 4}
    - {name: wall_s, centre: [0, -20], size: [60, 0.3], height: 4}
    - {name: crate, centre: [8, 4], size: [1, 1], height: 1, yaw_deg: 20}
  cylinders:
    - {name: post, centre: [4, -3], radius: 0.2, height: 2}
trajectory:
  start: [0, 0]
  heading_deg: 0
  segments: [{line: 3}, {arc: {radius: 3, turn_deg: 60}}, {line: 2}]
robot: {speed_mps: 1.5, wait_before_s: 1, wait_after_s: 0.5, lidar_mount: {xyz: [0.2, 0, 0.7], yaw_deg: 2}}
lidar: {rpm: 600, return_mode: dual, range_noise_m: 0.01}
gnss: {noise_h_m: 0.02, noise_v_m: 0.03, correlation_s: 5, faults: [{kind: lost, from_s: 4.0, to_s: 4.5}]}
imu: {angle_noise_deg: 0.05, heading_bias_deg: 0.3, magnetic_declination_deg: -8.5}
evaluation:
  circle_diameter_m: 12
  rect_height_m: 6
  rect_width_m: 12
  look_ahead_m: 5
  corridor_width_m: 12
  keyframes: [{name: start, position: [1.5, 0], heading_rad: 0}]
)";

class RunFolder : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::filesystem::path(std::filesystem::temp_directory_path() /
                                     ("trajroi_sim_test_" + std::to_string(::getpid())));
    const Scenario s = parse_scenario(kDriveScenario, "drive.yaml");
    report_ = new RunReport(write_run(s, kDriveScenario, *dir_));
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
    delete report_;
  }
  static std::filesystem::path* dir_;
  static RunReport* report_;
};
std::filesystem::path* RunFolder::dir_ = nullptr;
RunReport* RunFolder::report_ = nullptr;

TEST_F(RunFolder, HoldsEveryFileAndNoTemporaryOne) {
  EXPECT_NO_THROW(require_run_folder(*dir_));
  for (const auto& entry : std::filesystem::directory_iterator(dir_->parent_path())) {
    EXPECT_EQ(entry.path().filename().string().find(".trajroi_sim_test_" + std::to_string(::getpid()) + ".partial"),
              std::string::npos);
  }
  EXPECT_GT(report_->realtime_factor(), 0.0);
  EXPECT_THROW(require_run_folder(dir_->parent_path()), std::runtime_error);
}

TEST_F(RunFolder, DecodedPointsMatchTheTruthExactly) {
  const eval::ScenarioRun run(*dir_);
  std::uint64_t points = 0, frames = 0;
  const vlp16::StreamCounters counters = run.for_each_frame([&](const vlp16::Frame& f, std::uint64_t first, double) {
    EXPECT_EQ(first, points);
    EXPECT_EQ(f.return_mode, vlp16::ReturnMode::kDual);
    points += f.points.size();
    ++frames;
  });
  EXPECT_EQ(points, report_->stats.points);
  EXPECT_EQ(run.labels().size(), points);
  EXPECT_EQ(counters.data_packets, report_->stats.data_packets);
  EXPECT_EQ(counters.lost_packets, 0u);
  EXPECT_EQ(counters.position_packets, report_->stats.position_packets);
  // One surface per ray: in dual mode every return is reported once, as both.
  EXPECT_EQ(counters.merged_returns, points);
}

TEST_F(RunFolder, DecodedPoseIsTheTruePoseWithinTheConfiguredNoise) {
  const eval::ScenarioRun run(*dir_);
  EXPECT_EQ(run.pose_counters().fixes, report_->stats.gnss_epochs);
  EXPECT_EQ(run.pose_counters().invalid_position, 4u);  // 0.5 s of lost fix at 8 Hz
  EXPECT_EQ(run.pose_counters().high_precision, report_->stats.gnss_epochs - 4);
  // While the fix is lost the gate refuses the pose, and says why.
  const std::int64_t start = run.scenario().start_utc_ns;
  EXPECT_EQ(run.poses().pose_at(start + 4'250'000'000).status, pose::PoseStatus::kFixTypeTooLow);
  EXPECT_TRUE(run.poses().pose_at(start + 3'800'000'000).valid());
  EXPECT_TRUE(run.poses().pose_at(start + 4'800'000'000).valid());
  EXPECT_EQ(run.pose_counters().attitudes, report_->stats.imu_frames);
  double worst_position = 0.0, worst_yaw_deg = 0.0;
  std::size_t checked = 0;
  const auto& truth = run.truth().poses();
  for (std::size_t i = 0; i < truth.size(); i += 997) {
    const pose::PoseQuery q = run.poses().pose_at(truth[i].t_ns);
    if (!q.valid()) continue;
    worst_position = std::max(worst_position, std::hypot(q.global_from_robot.translation().x() - truth[i].x_m,
                                                         q.global_from_robot.translation().y() - truth[i].y_m));
    const double yaw = std::atan2(q.global_from_robot.linear()(1, 0), q.global_from_robot.linear()(0, 0));
    worst_yaw_deg = std::max(worst_yaw_deg, std::abs(std::remainder(yaw - truth[i].yaw_rad, 2 * kPi)) * 180.0 / kPi);
    ++checked;
  }
  EXPECT_GT(checked, 100u);
  // GNSS: σ = 2 cm per axis (Gauss–Markov) → 4σ horizontally; plus the linear interpolation
  // of an 8 Hz fix on a 3 m curve at 1.5 m/s (chord sagitta ≈ 1.5 cm).
  EXPECT_LT(worst_position, 0.11);
  EXPECT_GT(worst_position, 0.001);  // the noise is there
  // IMU: 0.3° heading bias + 4σ of 0.05° noise, plus interpolation between 61.5 Hz samples.
  EXPECT_LT(worst_yaw_deg, 0.3 + 0.2 + 0.6);
  EXPECT_GT(worst_yaw_deg, 0.2);
}

TEST_F(RunFolder, KeyframeEvaluationRuns) {
  const eval::ScenarioRun run(*dir_);
  const auto cases = eval::keyframe_cases(run, eval::PoseMode::kPerFiring);
  ASSERT_EQ(cases.size(), 1u);
  const eval::KeyframeRow row =
      eval::run_keyframe_row(run, cases[0], eval::RoiShape::kCircular, 25, 2, eval::PoseMode::kPerFiring);
  EXPECT_EQ(row.confusion.total(), cases[0].points.size());
  EXPECT_GT(row.confusion.tp, 1000u);
  EXPECT_GT(row.confusion.recall(), 0.95);
}

}  // namespace
}  // namespace trajroi::sim
