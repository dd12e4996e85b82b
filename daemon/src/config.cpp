#include "trajroi/daemon/config.hpp"

#include <arpa/inet.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "trajroi/config/origin.hpp"
#include "trajroi/config/text_file.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::daemon {
namespace {

using config::ConfigError;
using config::MapReader;

constexpr double kDegToRad = std::numbers::pi / 180.0;

std::filesystem::path resolve(const std::filesystem::path& base_dir, const std::string& value) {
  if (value.empty()) return {};
  const std::filesystem::path p(value);
  return p.is_absolute() ? p : (base_dir / p).lexically_normal();
}

std::size_t count(MapReader& m, std::string_view key, std::size_t fallback, std::size_t lo, std::size_t hi) {
  const std::int64_t v = m.integer(key, static_cast<std::int64_t>(fallback));
  m.require(v >= static_cast<std::int64_t>(lo) && v <= static_cast<std::int64_t>(hi), key,
            "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<std::size_t>(v);
}

std::uint16_t port(MapReader& m, std::string_view key, std::uint16_t fallback) {
  const std::int64_t v = m.integer(key, fallback);
  m.require(v >= 0 && v <= 65535, key, "must be a UDP port 0 … 65535");
  return static_cast<std::uint16_t>(v);
}

// A dotted IPv4 address; `allow_empty` for an optional one.
std::string ipv4(MapReader& m, std::string_view key, const char* fallback, bool allow_empty) {
  std::string text = m.text(key, fallback);
  in_addr parsed{};
  m.require((allow_empty && text.empty()) || inet_pton(AF_INET, text.c_str(), &parsed) == 1, key,
            "must be a dotted IPv4 address");
  return text;
}

Eigen::Isometry3d read_mounting(MapReader m) {
  const auto xyz = m.numbers("xyz", {0.0, 0.0, 0.0});
  const double roll = m.number("roll_deg", 0.0) * kDegToRad;
  const double pitch = m.number("pitch_deg", 0.0) * kDegToRad;
  const double yaw = m.number("yaw_deg", 0.0) * kDegToRad;
  m.finish();
  return roi::pose_from_xyz_rpy(Eigen::Vector3d(xyz[0], xyz[1], xyz[2]), roll, pitch, yaw);
}

void read_serial(MapReader& m, DaemonConfig::Serial& s) {
  s.device = m.text("device", "");
  s.baud = static_cast<int>(m.integer("baud", 115200));
  m.require(s.baud >= 1200 && s.baud <= 4'000'000, "baud", "must be a serial baud rate (1200 … 4000000)");
  s.delay_s = m.number("delay_s", 0.0);
  m.require(s.delay_s >= 0.0 && s.delay_s < 1.0, "delay_s", "must be in [0, 1) s");
}

ThreadConfig read_thread(MapReader& parent, std::string_view key) {
  ThreadConfig t;
  if (!parent.has(key)) return t;
  MapReader m = parent.map(key);
  const std::string policy = m.choice("policy", {"other", "fifo", "rr"}, "other");
  t.policy = policy == "fifo" ? SchedPolicy::kFifo : policy == "rr" ? SchedPolicy::kRr : SchedPolicy::kOther;
  t.priority = static_cast<int>(m.integer("priority", t.policy == SchedPolicy::kOther ? 0 : 50));
  if (t.policy == SchedPolicy::kOther) {
    m.require(t.priority == 0, "priority", "must be 0 with policy 'other'");
  } else {
    m.require(t.priority >= 1 && t.priority <= 99, "priority", "must be 1 … 99 with policy fifo or rr");
  }
  if (m.has("cpus")) {
    for (const double cpu : m.number_list("cpus", 1, 1024)) {
      m.require(cpu >= 0.0 && cpu < 1024.0 && cpu == std::floor(cpu), "cpus", "must list CPU indices 0 … 1023");
      t.cpus.push_back(static_cast<int>(cpu));
    }
  }
  m.finish();
  return t;
}

}  // namespace

DaemonConfig parse_daemon_config(std::string_view text, const std::filesystem::path& file) {
  DaemonConfig c;
  c.file = file;
  const std::filesystem::path dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  MapReader r = MapReader::parse(text, file.string());

  {
    MapReader g = r.map("global_frame");
    const config::Origin o = config::read_origin(g.map("origin"));
    c.origin = pose::Geodetic{o.lat_deg, o.lon_deg, o.height_m};
    g.finish();
  }
  {
    MapReader t = r.map("trajectory");
    c.trajectory_file = resolve(dir, t.text("file"));
    t.finish();
  }
  {
    MapReader l = r.map("lidar");
    (void)l.choice("model", {"VLP-16"}, "VLP-16");
    c.lidar.calibration = resolve(dir, l.text("calibration", ""));
    if (l.has("mounting")) c.lidar.robot_from_lidar = read_mounting(l.map("mounting"));
    c.lidar.min_range_m = l.non_negative("min_range_m", 0.0);
    c.lidar.max_range_m = l.positive("max_range_m", 130.0);
    l.require(c.lidar.max_range_m > c.lidar.min_range_m, "max_range_m", "must exceed min_range_m");
    c.lidar.cut_azimuth_deg = l.number("cut_azimuth_deg", 0.0);
    l.require(c.lidar.cut_azimuth_deg >= 0.0 && c.lidar.cut_azimuth_deg < 360.0, "cut_azimuth_deg",
              "must be in [0, 360)");
    c.lidar.bind_address = ipv4(l, "bind_address", "0.0.0.0", false);
    c.lidar.sensor_address = ipv4(l, "sensor_address", "", true);
    l.require(c.lidar.sensor_address != "0.0.0.0", "sensor_address", "must name one host (empty accepts any)");
    c.lidar.data_port = port(l, "data_port", 2368);
    c.lidar.position_port = port(l, "position_port", 8308);
    c.lidar.receive_buffer_bytes =
        static_cast<int>(count(l, "receive_buffer_bytes", 4U << 20, 65536, std::size_t{1} << 30));
    l.finish();
  }
  {
    MapReader g = r.map("gnss");
    read_serial(g, c.gnss);
    const auto a = g.numbers("antenna", {0.0, 0.0, 0.0});
    c.gnss_antenna_m = Eigen::Vector3d(a[0], a[1], a[2]);
    g.finish();
  }
  {
    MapReader m = r.map("imu");
    read_serial(m, c.imu);
    c.magnetic_declination_deg = m.number("magnetic_declination_deg", 0.0);
    m.require(std::abs(c.magnetic_declination_deg) <= 180.0, "magnetic_declination_deg", "must be in [-180, 180]");
    if (m.has("mounting")) {
      const Eigen::Isometry3d t = read_mounting(m.map("mounting"));
      c.robot_from_imu = Eigen::Quaterniond(t.linear());
    }
    m.finish();
  }
  {
    MapReader p = r.map("pose", true);
    const std::string mode = p.choice("mode", {"per_firing", "per_sweep"}, "per_firing");
    c.pose_mode = mode == "per_sweep" ? PoseMode::kPerSweep : PoseMode::kPerFiring;
    c.gate.min_fix_type = static_cast<std::uint8_t>(count(p, "min_fix_type", 3, 1, 5));
    c.gate.require_gnss_fix_ok = p.boolean("require_gnss_fix_ok", true);
    c.gate.max_h_acc_m = p.positive("max_h_acc_m", 0.5);
    c.gate.require_rtk_fixed = p.boolean("require_rtk_fixed", false);
    c.gate.max_extrapolation_ns = std::llround(p.non_negative("max_extrapolation_s", 0.25) * 1e9);
    c.gate.max_gap_ns = std::llround(p.positive("max_gap_s", 1.0) * 1e9);
    c.pose_capacity = count(p, "buffer_samples", 4096, 16, 1U << 20);
    p.finish();
  }
  {
    MapReader o = r.map("roi");
    const std::string shape = o.choice("shape", {"circular", "rectangular"}, "circular");
    c.roi.shape = shape == "rectangular" ? RoiShape::kRectangular : RoiShape::kCircular;
    c.roi.circle_diameter_m = o.positive("circle_diameter_m", 28.0);
    c.roi.rect_height_m = o.positive("rect_height_m", 12.0);
    c.roi.rect_width_m = o.positive("rect_width_m", 28.0);
    c.roi.spacing_ratio = o.positive("spacing_ratio", 0.25);
    c.roi.look_ahead_m = o.non_negative("look_ahead_m", 42.0);
    c.roi.z_min_m = o.number("z_min_m", -std::numeric_limits<double>::infinity());
    c.roi.z_max_m = o.number("z_max_m", std::numeric_limits<double>::infinity());
    o.require(c.roi.z_min_m <= c.roi.z_max_m, "z_max_m", "must be >= z_min_m");
    if (o.has("speed_scaling")) {
      MapReader s = o.map("speed_scaling");
      c.roi.look_ahead_per_mps_s = s.non_negative("look_ahead_s", 0.0);
      c.roi.width_per_mps_s = s.non_negative("width_s", 0.0);
      c.roi.max_speed_mps = s.positive("max_speed_mps", 5.0);
      s.finish();
    }
    const double along = c.roi.shape == RoiShape::kCircular ? c.roi.circle_diameter_m : c.roi.rect_height_m;
    o.require(c.roi.look_ahead_m / (c.roi.spacing_ratio * along) < 100000.0, "spacing_ratio",
              "gives more than 100000 centres over the look-ahead");
    o.finish();
  }
  {
    MapReader l = r.map("lcm", true);
    c.lcm.url = l.text("url", c.lcm.url);
    if (l.has("channels")) {
      MapReader ch = l.map("channels");
      const auto channel = [&ch](std::string_view key, std::string& name) {
        name = ch.text(key, name);
        ch.require(!name.empty(), key, "must not be empty");
      };
      channel("points", c.lcm.points);
      channel("pose", c.lcm.pose);
      channel("roi", c.lcm.roi);
      channel("status", c.lcm.status);
      channel("trajectory", c.lcm.trajectory);
      ch.finish();
    }
    l.finish();
  }
  {
    MapReader b = r.map("buffers", true);
    c.buffers.lidar_packets = count(b, "lidar_packets", c.buffers.lidar_packets, 16, 1U << 20);
    c.buffers.serial_chunks = count(b, "serial_chunks", c.buffers.serial_chunks, 16, 1U << 20);
    c.buffers.sweeps = count(b, "sweeps", c.buffers.sweeps, 2, 1024);
    c.buffers.max_points_per_sweep = count(b, "max_points_per_sweep", c.buffers.max_points_per_sweep, 1024, 1U << 24);
    b.finish();
  }
  {
    MapReader l = r.map("logging", true);
    c.logging.level = l.choice("level", {"trace", "debug", "info", "warn", "error", "critical", "off"}, "info");
    c.logging.warning_interval_s = l.non_negative("warning_interval_s", 5.0);
    l.finish();
  }
  {
    MapReader rt = r.map("realtime", true);
    c.realtime.lock_memory = rt.boolean("lock_memory", false);
    if (rt.has("threads")) {
      MapReader t = rt.map("threads");
      c.realtime.lidar = read_thread(t, "lidar");
      c.realtime.gnss = read_thread(t, "gnss");
      c.realtime.imu = read_thread(t, "imu");
      c.realtime.processing = read_thread(t, "processing");
      c.realtime.publisher = read_thread(t, "publisher");
      t.finish();
    }
    rt.finish();
  }
  r.finish();
  return c;
}

DaemonConfig load_daemon_config(const std::filesystem::path& file) {
  return parse_daemon_config(config::read_text_file(file), file);
}

}  // namespace trajroi::daemon
