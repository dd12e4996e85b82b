#pragma once

// trajroid's configuration, read strictly from YAML (config/trajroid.yaml documents every
// key). Relative paths are resolved against the configuration file's folder. Every problem
// throws config::ConfigError naming the file, line, key and value.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/pose/geodetic.hpp"
#include "trajroi/pose/pose_buffer.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::daemon {

// Exit code for a configuration error (sysexits.h EX_CONFIG); systemd does not restart it.
inline constexpr int kExitConfig = 78;

using roi::RoiShape;
enum class PoseMode : std::uint8_t { kPerFiring, kPerSweep };
enum class TrajectoryCoordinates : std::uint8_t { kGlobalXy, kLatLon };

// Where the robot's pose comes from (pose.source).
enum class PoseSource : std::uint8_t {
  kGnssImu,  // u-blox position + VN-100 attitude
  kGnss,     // u-blox alone: heading from the course over ground or a moving-base baseline
  kLcm,      // the robot's localization publishes pose_input_t (lcm.channels.pose_input)
  kFixed,    // a static pose from the configuration
};
[[nodiscard]] std::string_view to_string(PoseSource source) noexcept;
enum class SchedPolicy : std::uint8_t { kOther, kFifo, kRr };

struct ThreadConfig {
  SchedPolicy policy = SchedPolicy::kOther;
  int priority = 0;       // 1 … 99 for fifo / rr
  std::vector<int> cpus;  // affinity; empty: any
};

// The most LiDARs one trajroid takes (`lidars:`).
inline constexpr std::size_t kMaxLidars = 8;

struct DaemonConfig {
  std::filesystem::path file;  // where it was read from

  pose::Geodetic origin;

  std::filesystem::path trajectory_file;  // CSV of x,y (global frame, m) or lat,lon (degrees)
  TrajectoryCoordinates trajectory_coordinates = TrajectoryCoordinates::kGlobalXy;  // without a header line

  // One LiDAR (`lidar:`), or each of several (`lidars:`, a list with names). `lidar` is always
  // the first of `lidars` (which holds at least one).
  struct Lidar {
    std::string name = "lidar";  // `lidars:` entries: required, unique (logs, status, the view)
    // auto (told from the packets' product id), vlp16, puck_lite, puck_hires, vlp32c, hdl32e.
    std::string model = "auto";
    std::filesystem::path calibration;  // velodyne/nebula YAML; empty: the manual's values
    Eigen::Isometry3d robot_from_lidar = Eigen::Isometry3d::Identity();
    double min_range_m = 0.0;
    double max_range_m = 130.0;
    double cut_azimuth_deg = 0.0;
    std::string bind_address = "0.0.0.0";
    std::string sensor_address;  // only datagrams from this IPv4 address; empty: any (counted)
    std::uint16_t data_port = 2368;
    std::uint16_t position_port = 8308;
    int receive_buffer_bytes = 4 << 20;
    bool share_ports = false;  // SO_REUSEADDR: other readers may bind the same ports (multicast)
  } lidar;
  std::vector<Lidar> lidars{Lidar{}};
  // The LiDARs to run: `lidars` when several, else the one `lidar` holds (read from lidar:, or
  // set in code).
  [[nodiscard]] std::vector<Lidar> all_lidars() const { return lidars.size() > 1 ? lidars : std::vector<Lidar>{lidar}; }
  // How messages name LiDAR `i`'s keys: "lidar" for one, "lidars[1]" with several.
  [[nodiscard]] std::string lidar_key(std::size_t i) const {
    return lidars.size() > 1 ? "lidars[" + std::to_string(i) + "]" : std::string("lidar");
  }
  // Several LiDARs: their sweeps merged into one points_t per time window (a sensor index per
  // point), or published one by one.
  struct LidarMerge {
    double max_wait_s = 0.1;  // after a window's first sweep, at most this for the others
    double silent_s = 0.5;    // a sensor without a sweep this long is not waited for (and named)
    bool per_sensor = false;  // true: each sensor's sweep published alone (sensor index set)
  } lidar_merge;
  // Several LiDARs whose sweeps go out merged (not each alone).
  [[nodiscard]] bool merges_sweeps() const noexcept { return lidars.size() > 1 && !lidar_merge.per_sensor; }

  struct Serial {
    std::string device;  // empty: this stream is not used live
    int baud = 115200;
    double delay_s = 0.0;
    bool configure = false;  // set the receiver's output each time the device opens
    double rate_hz = 0.0;    // … at this rate (gnss default 5 Hz, imu 40 Hz)
  };
  Serial gnss = [] {
    Serial s;
    s.rate_hz = 5.0;
    return s;
  }();
  Eigen::Vector3d gnss_antenna_m = Eigen::Vector3d::Zero();  // in the robot frame
  // RTK corrections written into the u-blox through gnss.device (corrections_link.hpp).
  struct GnssCorrections {
    std::string url;               // ntrip://, tcp://, udp://, serial://, lcm:// (corrections_url.hpp); empty: none
    double gga_interval_s = 10.0;  // NTRIP: the rover's GGA to the caster this often (0: never)
    double stall_s = 10.0;         // no byte for this long: the stream is lost (reconnect)
    double max_age_s = 5.0;        // newest frame written longer ago than this: warned
  } gnss_corrections;
  Serial imu = [] {
    Serial s;
    s.rate_hz = 40.0;
    return s;
  }();
  double magnetic_declination_deg = 0.0;
  Eigen::Quaterniond robot_from_imu = Eigen::Quaterniond::Identity();

  PoseSource pose_source = PoseSource::kGnssImu;
  struct GnssHeading {                          // pose.source gnss
    double min_speed_mps = 1.0;                 // course over ground trusted above this
    double max_heading_acc_deg = 5.0;           // … and with headAcc / accHeading at most this
    double baseline_yaw_deg = 0.0;              // moving-base baseline (reference → rover) in the robot frame
    std::optional<double> initial_heading_deg;  // true bearing until the GNSS gives one
  } gnss_heading;
  Eigen::Isometry3d fixed_pose = Eigen::Isometry3d::Identity();  // pose.source fixed: global_from_robot
  PoseMode pose_mode = PoseMode::kPerFiring;
  // The gate's defaults are what a standalone receiver passes (the u-blox M8/F9 without
  // corrections report 1–3 m; the data set's receivers 0.98–2.5 m) at its common rates (4 Hz
  // needs 0.25 s + the delay past the newest fix); tighten them for RTK.
  pose::PoseGate gate = [] {
    pose::PoseGate g;
    g.max_h_acc_m = 5.0;
    g.max_extrapolation_ns = 500'000'000;
    return g;
  }();
  std::size_t pose_capacity = 4096;

  struct Roi {
    RoiShape shape = RoiShape::kCircular;
    double circle_diameter_m = 28.0;
    double rect_height_m = 12.0;
    double rect_width_m = 28.0;
    double spacing_ratio = 0.25;
    double look_ahead_m = 42.0;
    double z_min_m = -std::numeric_limits<double>::infinity();
    double z_max_m = std::numeric_limits<double>::infinity();
    double look_ahead_per_mps_s = 0.0;  // look-ahead grows by speed × this
    double width_per_mps_s = 0.0;       // diameter / rectangle width grows by speed × this
    double max_speed_mps = 5.0;         // speed used for the growth is capped here
  } roi;

  struct Lcm {
    std::string url = "udpm://239.255.76.67:7667?ttl=0";
    std::string points = "TRAJROI_POINTS";
    std::string pose = "TRAJROI_POSE";
    std::string roi = "TRAJROI_ROI";
    std::string status = "TRAJROI_STATUS";
    std::string trajectory = "TRAJROI_TRAJECTORY";
    std::string pose_input = "TRAJROI_POSE_INPUT";  // pose.source lcm
    std::string raw_points = "TRAJROI_RAW_POINTS";  // outputs.raw_points
    std::string active_trajectory = "TRAJROI_ACTIVE_TRAJECTORY";
  } lcm;

  // Optional outputs, for viewers.
  struct Outputs {
    bool raw_points = false;                // every decoded point before the ROI, decimated
    std::size_t raw_points_decimation = 4;  // one point in this many (by its index in the sweep)
  } outputs;

  struct Buffers {
    std::size_t lidar_packets = 4096;  // ≈ 2.7 s of dual-return packets
    std::size_t serial_chunks = 1024;
    std::size_t sweeps = 8;
    std::size_t max_points_per_sweep = 131072;  // a 5 Hz dual-return sweep is ≈ 115 000
  } buffers;

  struct Time {
    double max_gnss_offset_s = 0.1;   // host UTC − GNSS UTC beyond this is warned (NTP/chrony off?)
    double max_lidar_offset_s = 0.1;  // host UTC − the VLP-16's PPS-locked UTC beyond this is warned
    std::optional<int> chrony_shm;    // GNSS time to chrony's `refclock SHM N` (none: off)
  } time;

  struct Logging {
    std::string level = "info";       // trace debug info warn error critical off
    double warning_interval_s = 5.0;  // per-packet warnings: at most one per interval and kind
  } logging;

  struct Realtime {
    bool lock_memory = false;  // mlockall(MCL_CURRENT | MCL_FUTURE)
    // Live: a sweep goes out on the processing thread when the publisher thread is idle.
    bool publish_from_processing = true;
    ThreadConfig lidar, gnss, imu, processing, publisher;
  } realtime;
};

// Empty when `url` is an LCM URL the daemon can use (provider udpm, memq, file or tcpq; for
// udpm an IPv4 multicast address, a port 1 … 65535, ttl 0 … 255), else what is wrong with it.
[[nodiscard]] std::string check_lcm_url(const std::string& url);

// The multicast group, port and options of a udpm:// URL (LCM's defaults 239.255.76.67:7667
// when the URL names none); nullopt for the other providers. The URL must have passed check_lcm_url.
struct LcmGroup {
  std::string address;
  int port = 7667;
  int ttl = 0;            // ?ttl= (liblcm's default: 0, this host only)
  int recv_buf_size = 0;  // ?recv_buf_size= bytes (0: the kernel's default)
};
[[nodiscard]] std::optional<LcmGroup> lcm_multicast_group(const std::string& url);

// Every effective value, one "section.key: value" line each, in config/trajroid.yaml's order
// and units (what --check-config prints; a test compares the file's documented defaults with
// the code's through it).
[[nodiscard]] std::string describe(const DaemonConfig& config);

// The reference of every key, as Markdown: one table per section (key, type, default,
// meaning), generated from the same table the parse and describe() walk (docs/configuration.md
// holds it; `trajroid --config-reference` prints it).
[[nodiscard]] std::string config_reference();

// Reads and checks a configuration. Throws config::ConfigError.
[[nodiscard]] DaemonConfig parse_daemon_config(std::string_view text, const std::filesystem::path& file);
[[nodiscard]] DaemonConfig load_daemon_config(const std::filesystem::path& file);

}  // namespace trajroi::daemon
