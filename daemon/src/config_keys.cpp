// The table of every configuration key (see config_keys.hpp): the keys of the pose, the ROI,
// LCM, buffers, time, logging and real time here, the sensors' in config_keys_sensors.cpp. The
// defaults are DaemonConfig's initialisers: each reader falls back on the value the key already
// has.
#include "config_keys.hpp"

#include <cmath>
#include <limits>

#include "config_key_makers.hpp"

namespace trajroi::daemon {
namespace {

using namespace config_keys_detail;

// A lcm.channels.* key.
ConfigKey channel_key(std::string_view path, std::string_view meaning, std::string DaemonConfig::Lcm::*name) {
  return {path,
          "text",
          meaning,
          false,
          [name](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
            c.lcm.*name = m.text(k, c.lcm.*name);
            m.require(!(c.lcm.*name).empty(), k, "must not be empty");
          },
          [name](const DaemonConfig& c) { return c.lcm.*name; }};
}

// A realtime.threads.* key.
ConfigKey thread_key(std::string_view path, std::string_view meaning, ThreadConfig DaemonConfig::Realtime::*thread) {
  return {path,
          "{policy: other | fifo | rr, priority: 1–99, cpus: [..]}",
          meaning,
          false,
          [thread](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
            c.realtime.*thread = read_thread(m, k);
          },
          [thread](const DaemonConfig& c) { return format_thread(c.realtime.*thread); }};
}

std::vector<ConfigKey> make_keys() {
  std::vector<ConfigKey> k;
  add_sensor_keys(k);
  // ---- pose
  k.push_back({"pose.source", "gnss_imu | gnss | lcm | fixed",
               "where the pose comes from: u-blox position + VN-100 attitude; the u-blox alone (heading from a "
               "moving-base baseline or the course over ground); the robot's localization (pose_input_t on "
               "lcm.channels.pose_input); a static pose (pose.fixed)",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 const std::string s = m.choice(key, {"gnss_imu", "gnss", "lcm", "fixed"}, to_string(c.pose_source));
                 c.pose_source = s == "gnss"    ? PoseSource::kGnss
                                 : s == "lcm"   ? PoseSource::kLcm
                                 : s == "fixed" ? PoseSource::kFixed
                                                : PoseSource::kGnssImu;
               },
               [](const DaemonConfig& c) { return std::string(to_string(c.pose_source)); }});
  k.push_back(real_key(
      "pose.gnss_heading.min_speed_mps", "number > 0",
      "source gnss: the course over ground is a heading only above this speed …", Sign::kPositive,
      [](auto& c) -> auto& { return c.gnss_heading.min_speed_mps; }));
  k.push_back(real_key(
      "pose.gnss_heading.max_heading_acc_deg", "number > 0",
      "… and with its accuracy (headAcc / accHeading) at most this; otherwise the last heading is held",
      Sign::kPositive, [](auto& c) -> auto& { return c.gnss_heading.max_heading_acc_deg; }));
  k.push_back({"pose.gnss_heading.baseline_yaw_deg", "number in [-180, 180]",
               "moving base → rover antenna direction in the robot frame (0: rear → front)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.gnss_heading.baseline_yaw_deg = m.number(key, c.gnss_heading.baseline_yaw_deg);
                 m.require(std::abs(c.gnss_heading.baseline_yaw_deg) <= 180.0, key, "must be in [-180, 180]");
               },
               [](const DaemonConfig& c) { return format_number(c.gnss_heading.baseline_yaw_deg); }});
  k.push_back({"pose.gnss_heading.initial_heading_deg", "number in [0, 360) or none",
               "true bearing used until the GNSS gives a heading (none: wait)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.gnss_heading.initial_heading_deg = optional_number(m, key);
                 if (const auto& b = c.gnss_heading.initial_heading_deg) {
                   m.require(*b >= 0.0 && *b < 360.0, key,
                             "must be a true bearing in [0, 360) (clockwise from north), or none");
                 }
               },
               [](const DaemonConfig& c) {
                 return c.gnss_heading.initial_heading_deg ? format_number(*c.gnss_heading.initial_heading_deg)
                                                           : std::string("none");
               }});
  k.push_back({"pose.fixed", "{xyz: [x, y, z], roll_deg, pitch_deg, yaw_deg}",
               "source fixed: global_from_robot (required with it)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 if (m.has(key)) c.fixed_pose = read_mounting(m.map(key));
               },
               [](const DaemonConfig& c) { return format_mounting(c.fixed_pose); }});
  k.push_back({"pose.mode", "per_firing | per_sweep",
               "per_firing: motion-compensated, one pose per 55.3 µs firing; per_sweep: one pose at the sweep's "
               "start (the paper's way)",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 const std::string mode = m.choice(key, {"per_firing", "per_sweep"},
                                                   c.pose_mode == PoseMode::kPerSweep ? "per_sweep" : "per_firing");
                 c.pose_mode = mode == "per_sweep" ? PoseMode::kPerSweep : PoseMode::kPerFiring;
               },
               [](const DaemonConfig& c) {
                 return std::string(c.pose_mode == PoseMode::kPerSweep ? "per_sweep" : "per_firing");
               }});
  k.push_back({"pose.min_fix_type", "integer in [1, 5]", "gate: u-blox fix type at least this (3: 3-D, 4: GNSS + DR)",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.gate.min_fix_type = static_cast<std::uint8_t>(count(m, key, c.gate.min_fix_type, 1, 5));
               },
               [](const DaemonConfig& c) { return format_number(c.gate.min_fix_type); }});
  k.push_back(flag_key(
      "pose.require_gnss_fix_ok", "gate: NAV-PVT's gnssFixOK flag set",
      [](auto& c) -> auto& { return c.gate.require_gnss_fix_ok; }));
  k.push_back(real_key(
      "pose.max_h_acc_m", "number > 0",
      "gate: horizontal accuracy estimate at most this (a standalone receiver reports 1–3 m; 0.05 "
      "insists on RTK-grade fixes)",
      Sign::kPositive, [](auto& c) -> auto& { return c.gate.max_h_acc_m; }));
  k.push_back({"pose.require_rtk", "none | float | fixed",
               "gate: at least this RTK carrier solution (NAV-PVT carrSoln; needs corrections: gnss.corrections)",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 if (m.has("require_rtk_fixed"))  // the boolean this key replaced
                   m.fail("require_rtk_fixed", "renamed: pose.require_rtk: fixed (or float, none)");
                 const std::string s =
                     m.choice(key, {"none", "float", "fixed"}, std::string(pose::to_string(c.gate.require_rtk)));
                 c.gate.require_rtk = s == "fixed"   ? pose::RtkSolution::kFixed
                                      : s == "float" ? pose::RtkSolution::kFloat
                                                     : pose::RtkSolution::kNone;
               },
               [](const DaemonConfig& c) { return std::string(pose::to_string(c.gate.require_rtk)); }});
  k.push_back(
      {"pose.max_extrapolation_s", "number ≥ 0",
       "gate: past the newest fix / attitude (a GNSS period + its delay: 0.5 covers 4 Hz and faster; a 1 Hz "
       "receiver needs 1.2)",
       false,
       [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
         c.gate.max_extrapolation_ns =
             std::llround(m.non_negative(key, static_cast<double>(c.gate.max_extrapolation_ns) * 1e-9) * 1e9);
       },
       [](const DaemonConfig& c) { return format_number(static_cast<double>(c.gate.max_extrapolation_ns) * 1e-9); }});
  k.push_back({"pose.max_gap_s", "number > 0", "gate: at most this between the two samples around a firing", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.gate.max_gap_ns = std::llround(m.positive(key, static_cast<double>(c.gate.max_gap_ns) * 1e-9) * 1e9);
               },
               [](const DaemonConfig& c) { return format_number(static_cast<double>(c.gate.max_gap_ns) * 1e-9); }});
  k.push_back(count_key(
      "pose.buffer_samples", "samples kept per stream", 16, std::size_t{1} << 20,
      [](auto& c) -> auto& { return c.pose_capacity; }));
  // ---- roi
  k.push_back({"roi.shape", "circular | rectangular", "the shape laid along the trajectory", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 const std::string s = m.choice(key, {"circular", "rectangular"}, roi::to_string(c.roi.shape));
                 c.roi.shape = s == "rectangular" ? RoiShape::kRectangular : RoiShape::kCircular;
               },
               [](const DaemonConfig& c) { return std::string(roi::to_string(c.roi.shape)); }});
  k.push_back(real_key(
      "roi.circle_diameter_m", "number > 0", "2r", Sign::kPositive,
      [](auto& c) -> auto& { return c.roi.circle_diameter_m; }));
  k.push_back(real_key(
      "roi.rect_height_m", "number > 0", "a, along the trajectory", Sign::kPositive,
      [](auto& c) -> auto& { return c.roi.rect_height_m; }));
  k.push_back(real_key(
      "roi.rect_width_m", "number > 0", "b, across the trajectory", Sign::kPositive,
      [](auto& c) -> auto& { return c.roi.rect_width_m; }));
  k.push_back(real_key(
      "roi.spacing_ratio", "number > 0", "d as a fraction of 2r (circles) or a (rectangles)", Sign::kPositive,
      [](auto& c) -> auto& { return c.roi.spacing_ratio; }));
  k.push_back(real_key(
      "roi.look_ahead_m", "number ≥ 0", "the chain's length ahead of the robot", Sign::kNonNegative,
      [](auto& c) -> auto& { return c.roi.look_ahead_m; }));
  k.push_back({"roi.z_min_m", "number or none", "lower height limit (global frame, m, inclusive; none: no limit)",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.roi.z_min_m = optional_number(m, key).value_or(-std::numeric_limits<double>::infinity());
               },
               [](const DaemonConfig& c) { return format_number(c.roi.z_min_m); }});
  k.push_back({"roi.z_max_m", "number or none", "upper height limit (global frame, m, inclusive; none: no limit)",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.roi.z_max_m = optional_number(m, key).value_or(std::numeric_limits<double>::infinity());
               },
               [](const DaemonConfig& c) { return format_number(c.roi.z_max_m); }});
  k.push_back(real_key(
      "roi.speed_scaling.look_ahead_s", "number ≥ 0", "the look-ahead grows by speed × this", Sign::kNonNegative,
      [](auto& c) -> auto& { return c.roi.look_ahead_per_mps_s; }));
  k.push_back(real_key(
      "roi.speed_scaling.width_s", "number ≥ 0", "the diameter / rectangle width grows by speed × this",
      Sign::kNonNegative, [](auto& c) -> auto& { return c.roi.width_per_mps_s; }));
  k.push_back(real_key(
      "roi.speed_scaling.max_speed_mps", "number > 0",
      "the speed used above is capped here; an unknown speed (a pose valid for < 0.1 s) grows the "
      "ROI as this cap does",
      Sign::kPositive, [](auto& c) -> auto& { return c.roi.max_speed_mps; }));
  // ---- lcm
  k.push_back({"lcm.url", "LCM URL (udpm, memq, file, tcpq)", "where the messages go; udpm ttl=0: this host only",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.lcm.url = m.text(key, c.lcm.url);
                 if (const std::string problem = check_lcm_url(c.lcm.url); !problem.empty()) m.fail(key, problem);
               },
               [](const DaemonConfig& c) { return c.lcm.url; }});
  k.push_back(channel_key("lcm.channels.points", "points_t: the kept points of each sweep, global frame",
                          &DaemonConfig::Lcm::points));
  k.push_back(channel_key("lcm.channels.pose", "pose_t: each sweep's pose, valid or not (with the reason)",
                          &DaemonConfig::Lcm::pose));
  k.push_back(
      channel_key("lcm.channels.roi", "roi_t: the chain each sweep was filtered against", &DaemonConfig::Lcm::roi));
  k.push_back(
      channel_key("lcm.channels.status", "status_t: health and counters, once a second", &DaemonConfig::Lcm::status));
  k.push_back(channel_key("lcm.channels.trajectory", "trajectory_t (input): replaces the active trajectory",
                          &DaemonConfig::Lcm::trajectory));
  k.push_back(channel_key("lcm.channels.pose_input", "pose_input_t (input, pose.source lcm): the robot's localization",
                          &DaemonConfig::Lcm::pose_input));
  k.push_back(channel_key("lcm.channels.raw_points",
                          "points_t (outputs.raw_points): each sweep's decoded points before the ROI, decimated",
                          &DaemonConfig::Lcm::raw_points));
  k.push_back(channel_key("lcm.channels.active_trajectory",
                          "trajectory_t: the active trajectory (global x/y, its id), as it changes and once a second",
                          &DaemonConfig::Lcm::active_trajectory));
  // ---- outputs
  k.push_back(flag_key(
      "outputs.raw_points",
      "publish each sweep's decoded points before the ROI (global frame, decimated) on lcm.channels.raw_points, for "
      "`trajroi view` to draw what the ROI removed",
      [](auto& c) -> auto& { return c.outputs.raw_points; }));
  k.push_back(count_key(
      "outputs.raw_points_decimation", "outputs.raw_points keeps one point in this many (by its index in the sweep)", 1,
      1000, [](auto& c) -> auto& { return c.outputs.raw_points_decimation; }));
  // ---- buffers, time, logging, realtime
  k.push_back(count_key(
      "buffers.lidar_packets", "ring of the LiDAR input (≈ 2.7 s of dual-return packets)", 16, std::size_t{1} << 20,
      [](auto& c) -> auto& { return c.buffers.lidar_packets; }));
  k.push_back(count_key(
      "buffers.serial_chunks", "ring of each serial input", 16, std::size_t{1} << 20,
      [](auto& c) -> auto& { return c.buffers.serial_chunks; }));
  k.push_back(count_key(
      "buffers.sweeps", "ring of finished sweeps, processing → publisher", 2, 1024,
      [](auto& c) -> auto& { return c.buffers.sweeps; }));
  k.push_back(count_key(
      "buffers.max_points_per_sweep",
      "kept points a sweep holds at most (a 5 Hz dual-return sweep has ≈ 115 000 points); more "
      "are counted as truncated",
      1024, std::size_t{1} << 24, [](auto& c) -> auto& { return c.buffers.max_points_per_sweep; }));
  k.push_back(real_key(
      "time.max_gnss_offset_s", "number > 0",
      "host UTC − GNSS UTC (NAV-PVT) beyond this is warned: is NTP / chrony running?", Sign::kPositive,
      [](auto& c) -> auto& { return c.time.max_gnss_offset_s; }));
  k.push_back(real_key(
      "time.max_lidar_offset_s", "number > 0",
      "host UTC − the VLP-16's PPS-locked UTC beyond this is warned: is chrony disciplining the host, the PPS right?",
      Sign::kPositive, [](auto& c) -> auto& { return c.time.max_lidar_offset_s; }));
  k.push_back({"time.chrony_shm", "none | integer in [0, 15]",
               "live: each NAV-PVT's UTC to chrony's `refclock SHM N` (the segment chronyd made; docs/time.md)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 const std::optional<double> unit = optional_number(m, key);
                 m.require(!unit || (*unit >= 0 && *unit <= 15 && *unit == std::floor(*unit)), key,
                           "must be none or an SHM unit 0 … 15 (chrony's `refclock SHM N`)");
                 c.time.chrony_shm = unit ? std::optional<int>(static_cast<int>(*unit)) : std::nullopt;
               },
               [](const DaemonConfig& c) {
                 return c.time.chrony_shm ? std::to_string(*c.time.chrony_shm) : std::string("none");
               }});
  k.push_back({"logging.level", "trace | debug | info | warn | error | critical | off", "the log's level", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.logging.level =
                     m.choice(key, {"trace", "debug", "info", "warn", "error", "critical", "off"}, c.logging.level);
               },
               [](const DaemonConfig& c) { return c.logging.level; }});
  k.push_back(real_key(
      "logging.warning_interval_s", "number ≥ 0",
      "warnings that can fire per packet: at most one per interval and kind", Sign::kNonNegative,
      [](auto& c) -> auto& { return c.logging.warning_interval_s; }));
  k.push_back(flag_key(
      "realtime.lock_memory", "mlockall; needs CAP_IPC_LOCK or LimitMEMLOCK (systemd/realtime.conf)",
      [](auto& c) -> auto& { return c.realtime.lock_memory; }));
  k.push_back(flag_key(
      "realtime.publish_from_processing",
      "live: the processing thread publishes the sweep it finished itself while the publisher thread is idle (no "
      "thread to wake between a sweep's last packet and its message); false: the publisher thread publishes every "
      "sweep",
      [](auto& c) -> auto& { return c.realtime.publish_from_processing; }));
  k.push_back(thread_key("realtime.threads.lidar",
                         "the LiDAR input thread, e.g. {policy: fifo, priority: 60, cpus: [1]}",
                         &DaemonConfig::Realtime::lidar));
  k.push_back(thread_key("realtime.threads.gnss", "the GNSS input thread", &DaemonConfig::Realtime::gnss));
  k.push_back(thread_key("realtime.threads.imu", "the IMU input thread", &DaemonConfig::Realtime::imu));
  k.push_back(thread_key("realtime.threads.processing", "the processing thread", &DaemonConfig::Realtime::processing));
  k.push_back(thread_key("realtime.threads.publisher", "the publisher thread", &DaemonConfig::Realtime::publisher));
  return k;
}

double size_along(const DaemonConfig::Roi& r) {
  return r.shape == RoiShape::kCircular ? r.circle_diameter_m : r.rect_height_m;
}

std::vector<ConfigSection> make_sections() {
  std::vector<ConfigSection> s;
  s.push_back({"global_frame", "The global frame", "ENU (x east, y north, z up) about an origin. Required.", true, {}});
  s.push_back({"trajectory", "The trajectory", "The active trajectory at start. Required.", true, {}});
  s.push_back({"lidar", "The LiDAR",
               "A Velodyne LiDAR on UDP (VLP-16, Puck LITE / Hi-Res, VLP-32C, HDL-32E). Several: lidars:, a list of "
               "these maps, each with a name.",
               false, [](MapReader& m, const DaemonConfig& c) {
                 m.require(c.lidar.max_range_m > c.lidar.min_range_m, "max_range_m", "must exceed min_range_m");
               }});
  s.push_back({"lidar_merge",
               "Several LiDARs",
               "With lidars: (a list of lidar: maps, each with a name): how their sweeps are merged.",
               false,
               {}});
  s.push_back({"gnss",
               "The GNSS receiver",
               "A u-blox receiver on a serial port: UBX NAV-PVT (+ NAV-HPPOSLLH) at 5–10 Hz.",
               false,
               {}});
  s.push_back({"imu",
               "The IMU",
               "A VectorNav VN-100 on a serial port, binary output: YawPitchRoll, Quaternion or DCM (with TimeStartup "
               "or TimeGps when present; else the receive time).",
               false,
               {}});
  s.push_back({"pose", "The pose", "Where the pose comes from, and the gate a sweep's pose must pass to be published.",
               false, [](MapReader& m, const DaemonConfig& c) {
                 m.require(c.pose_source != PoseSource::kFixed || m.has("fixed"), "fixed",
                           "must be given with source: fixed ({xyz: [x, y, z], yaw_deg: …})");
               }});
  s.push_back({"roi", "The ROI",
               "The paper's trajectory ROI, placed each sweep from the robot's projection on the trajectory.", false,
               [](MapReader& m, const DaemonConfig& c) {
                 m.require(c.roi.z_min_m <= c.roi.z_max_m, "z_max_m", "must be >= z_min_m");
                 m.require(c.roi.look_ahead_m / (c.roi.spacing_ratio * size_along(c.roi)) < 100000.0, "spacing_ratio",
                           "gives more than 100000 centres over the look-ahead");
               }});
  s.push_back({"lcm", "LCM", "Where the messages are published and read.", false, {}});
  s.push_back({"buffers",
               "Buffers",
               "Preallocated (and, live, resident) at start; a full ring drops the newest item (counted).",
               false,
               {}});
  s.push_back({"time",
               "Time",
               "Published stamps are CLOCK_MONOTONIC (t_ns) and UTC (utc_ns) with its source: the VLP-16's PPS-locked "
               "clock when its position packets say so, else the host's CLOCK_REALTIME.",
               false,
               {}});
  s.push_back({"logging", "Logging", "", false, {}});
  s.push_back(
      {"realtime", "Real time", "Per thread: the scheduling policy, priority and CPUs; locked memory.", false, {}});
  return s;
}

}  // namespace

const std::vector<ConfigKey>& config_keys() {
  static const std::vector<ConfigKey> keys = make_keys();
  return keys;
}

const std::vector<ConfigSection>& config_sections() {
  static const std::vector<ConfigSection> sections = make_sections();
  return sections;
}

}  // namespace trajroi::daemon
