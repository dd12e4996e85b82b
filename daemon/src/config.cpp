#include "trajroi/daemon/config.hpp"

#include <arpa/inet.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>
#include <vector>

#include "trajroi/config/origin.hpp"
#include "trajroi/config/text_file.hpp"
#include "trajroi/pose/attitude.hpp"
#include "trajroi/roi/transform.hpp"
#include "trajroi/serial/serial_port_source.hpp"

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

// A number, or `none` (also when the key is left out).
std::optional<double> optional_number(MapReader& m, std::string_view key) {
  if (m.text(key, "none") == "none") return std::nullopt;
  return m.number(key);
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
  // A device that does not exist yet is no configuration error (a USB receiver can appear
  // after the daemon starts: a run-time fault, said and retried); one that exists must be
  // a terminal or serial device.
  struct stat st {};
  m.require(s.device.empty() || ::stat(s.device.c_str(), &st) != 0 || S_ISCHR(st.st_mode), "device",
            "exists but is not a character device (a serial port or pseudo-terminal)");
  s.baud = static_cast<int>(m.integer("baud", 115200));
  m.require(serial::is_supported_baud(s.baud), "baud", "must be one of " + serial::supported_bauds_text());
  s.delay_s = m.number("delay_s", 0.0);
  m.require(s.delay_s >= 0.0 && s.delay_s < 1.0, "delay_s", "must be in [0, 1) s");
  s.configure = m.boolean("configure", false);
  s.rate_hz = m.positive("rate_hz", s.rate_hz);
  m.require(s.rate_hz <= 800.0, "rate_hz", "must be at most 800 Hz");
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

// The key=value options after '?' in a udpm:// URL's rest (after "udpm://"), in order.
std::vector<std::pair<std::string, std::string>> udpm_options(const std::string& rest) {
  std::vector<std::pair<std::string, std::string>> options;
  const std::size_t question = rest.find('?');
  std::size_t at = question == std::string::npos ? rest.size() : question + 1;
  while (at < rest.size()) {
    const std::size_t end = std::min(rest.find('&', at), rest.size());
    const std::string option = rest.substr(at, end - at);
    const std::size_t eq = option.find('=');
    options.emplace_back(option.substr(0, eq), eq == std::string::npos ? "" : option.substr(eq + 1));
    at = end + 1;
  }
  return options;
}

}  // namespace

std::optional<LcmGroup> lcm_multicast_group(const std::string& url) {
  if (!url.starts_with("udpm://")) return std::nullopt;
  const std::string rest = url.substr(7);
  const std::string target = rest.substr(0, rest.find('?'));
  LcmGroup group;
  const std::size_t colon = target.find(':');
  group.address = target.substr(0, colon);
  if (group.address.empty()) group.address = "239.255.76.67";
  if (colon != std::string::npos) group.port = std::stoi(target.substr(colon + 1));
  // Options as check_lcm_url accepts them (checked there); others are ignored here.
  for (const auto& [key, value] : udpm_options(rest)) {
    if (key == "ttl") group.ttl = std::stoi(value);
    if (key == "recv_buf_size") group.recv_buf_size = std::stoi(value);
  }
  return group;
}

std::string check_lcm_url(const std::string& url) {
  const std::size_t scheme_end = url.find("://");
  if (scheme_end == std::string::npos) return "must be an LCM URL, provider://[address[:port]][?options]";
  const std::string provider = url.substr(0, scheme_end);
  if (provider != "udpm" && provider != "memq" && provider != "file" && provider != "tcpq") {
    return "provider '" + provider + "' is not one of udpm, memq, file, tcpq";
  }
  if (provider != "udpm") return {};
  const std::string rest = url.substr(scheme_end + 3);
  const std::string target = rest.substr(0, rest.find('?'));
  const std::string address = target.substr(0, target.find(':'));
  if (!address.empty()) {
    in_addr parsed{};
    if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) return "address '" + address + "' is not an IPv4 address";
    const std::uint32_t first = ntohl(parsed.s_addr) >> 24;
    if (first < 224 || first > 239) return "address '" + address + "' is not a multicast address (224–239.x.x.x)";
  }
  const auto whole_number = [](const std::string& text, long lo, long hi) {
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || text.size() > 9) return false;
    const long v = std::stol(text);
    return v >= lo && v <= hi;
  };
  if (target.find(':') != std::string::npos) {
    const std::string port_text = target.substr(target.find(':') + 1);
    if (!whole_number(port_text, 1, 65535)) return "port '" + port_text + "' is not a UDP port 1 … 65535";
  }
  for (const auto& [key, value] : udpm_options(rest)) {
    if (key == "ttl") {
      if (!whole_number(value, 0, 255)) return "ttl '" + value + "' is not 0 … 255";
    } else if (key == "recv_buf_size") {
      if (!whole_number(value, 1, 1 << 30)) return "recv_buf_size '" + value + "' is not a byte count";
    } else {
      return "option '" + key + "' is not one of ttl, recv_buf_size";
    }
  }
  return {};
}

std::string_view to_string(PoseSource source) noexcept {
  switch (source) {
    case PoseSource::kGnssImu:
      return "gnss_imu";
    case PoseSource::kGnss:
      return "gnss";
    case PoseSource::kLcm:
      return "lcm";
    case PoseSource::kFixed:
      return "fixed";
  }
  return "unknown";
}

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
    c.trajectory_coordinates = t.choice("coordinates", {"global_xy", "lat_lon"}, "global_xy") == "lat_lon"
                                   ? TrajectoryCoordinates::kLatLon
                                   : TrajectoryCoordinates::kGlobalXy;
    t.finish();
  }
  {
    MapReader l = r.map("lidar", true);
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
    c.lidar.share_ports = l.boolean("share_ports", false);
    l.finish();
  }
  {
    MapReader g = r.map("gnss", true);
    read_serial(g, c.gnss);
    const auto a = g.numbers("antenna", {0.0, 0.0, 0.0});
    c.gnss_antenna_m = Eigen::Vector3d(a[0], a[1], a[2]);
    g.finish();
  }
  {
    MapReader m = r.map("imu", true);
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
    const std::string source = p.choice("source", {"gnss_imu", "gnss", "lcm", "fixed"}, "gnss_imu");
    c.pose_source = source == "gnss"    ? PoseSource::kGnss
                    : source == "lcm"   ? PoseSource::kLcm
                    : source == "fixed" ? PoseSource::kFixed
                                        : PoseSource::kGnssImu;
    if (p.has("gnss_heading")) {
      MapReader h = p.map("gnss_heading");
      c.gnss_heading.min_speed_mps = h.positive("min_speed_mps", c.gnss_heading.min_speed_mps);
      c.gnss_heading.max_heading_acc_deg = h.positive("max_heading_acc_deg", c.gnss_heading.max_heading_acc_deg);
      c.gnss_heading.baseline_yaw_deg = h.number("baseline_yaw_deg", 0.0);
      h.require(std::abs(c.gnss_heading.baseline_yaw_deg) <= 180.0, "baseline_yaw_deg", "must be in [-180, 180]");
      c.gnss_heading.initial_heading_deg = optional_number(h, "initial_heading_deg");
      if (const auto& b = c.gnss_heading.initial_heading_deg) {
        h.require(*b >= 0.0 && *b < 360.0, "initial_heading_deg",
                  "must be a true bearing in [0, 360) (clockwise from north), or none");
      }
      h.finish();
    }
    if (c.pose_source == PoseSource::kFixed) {
      p.require(p.has("fixed"), "fixed", "must be given with source: fixed ({xyz: [x, y, z], yaw_deg: …})");
    }
    if (p.has("fixed")) c.fixed_pose = read_mounting(p.map("fixed"));
    const std::string mode = p.choice("mode", {"per_firing", "per_sweep"}, "per_firing");
    c.pose_mode = mode == "per_sweep" ? PoseMode::kPerSweep : PoseMode::kPerFiring;
    c.gate.min_fix_type = static_cast<std::uint8_t>(count(p, "min_fix_type", 3, 1, 5));
    c.gate.require_gnss_fix_ok = p.boolean("require_gnss_fix_ok", true);
    c.gate.max_h_acc_m = p.positive("max_h_acc_m", c.gate.max_h_acc_m);
    c.gate.require_rtk_fixed = p.boolean("require_rtk_fixed", false);
    c.gate.max_extrapolation_ns = std::llround(
        p.non_negative("max_extrapolation_s", static_cast<double>(c.gate.max_extrapolation_ns) * 1e-9) * 1e9);
    c.gate.max_gap_ns = std::llround(p.positive("max_gap_s", 1.0) * 1e9);
    c.pose_capacity = count(p, "buffer_samples", 4096, 16, 1U << 20);
    p.finish();
  }
  {
    MapReader o = r.map("roi", true);
    const std::string shape = o.choice("shape", {"circular", "rectangular"}, "circular");
    c.roi.shape = shape == "rectangular" ? RoiShape::kRectangular : RoiShape::kCircular;
    c.roi.circle_diameter_m = o.positive("circle_diameter_m", 28.0);
    c.roi.rect_height_m = o.positive("rect_height_m", 12.0);
    c.roi.rect_width_m = o.positive("rect_width_m", 28.0);
    c.roi.spacing_ratio = o.positive("spacing_ratio", 0.25);
    c.roi.look_ahead_m = o.non_negative("look_ahead_m", 42.0);
    c.roi.z_min_m = optional_number(o, "z_min_m").value_or(-std::numeric_limits<double>::infinity());
    c.roi.z_max_m = optional_number(o, "z_max_m").value_or(std::numeric_limits<double>::infinity());
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
    if (const std::string problem = check_lcm_url(c.lcm.url); !problem.empty()) l.fail("url", problem);
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
      channel("pose_input", c.lcm.pose_input);
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
    MapReader t = r.map("time", true);
    c.time.max_gnss_offset_s = t.positive("max_gnss_offset_s", c.time.max_gnss_offset_s);
    t.finish();
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

namespace {

std::string format_number(double v) {
  if (std::isinf(v)) return "none";  // an absent limit
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

// "[x, y, z]" (appended piecewise: GCC 12's -Wrestrict misfires on "[" + std::string).
std::string format_vector(const Eigen::Vector3d& v) {
  std::string out("[");
  out.append(format_number(v.x())).append(", ").append(format_number(v.y())).append(", ");
  out.append(format_number(v.z())).append("]");
  return out;
}

std::string format_mounting(const Eigen::Isometry3d& t) {
  const pose::RollPitchYaw rpy = pose::roll_pitch_yaw(Eigen::Quaterniond(t.linear()));
  constexpr double kRadToDeg = 180.0 / std::numbers::pi;
  std::string out("{xyz: ");
  out.append(format_vector(t.translation())).append(", roll_deg: ").append(format_number(rpy.roll_rad * kRadToDeg));
  out.append(", pitch_deg: ").append(format_number(rpy.pitch_rad * kRadToDeg));
  out.append(", yaw_deg: ").append(format_number(rpy.yaw_rad * kRadToDeg)).append("}");
  return out;
}

std::string format_thread(const ThreadConfig& t) {
  std::string out = t.policy == SchedPolicy::kFifo ? "{policy: fifo"
                    : t.policy == SchedPolicy::kRr ? "{policy: rr"
                                                   : "{policy: other";
  if (t.policy != SchedPolicy::kOther) out += ", priority: " + std::to_string(t.priority);
  if (!t.cpus.empty()) {
    out += ", cpus: [";
    for (std::size_t i = 0; i < t.cpus.size(); ++i) {
      if (i > 0) out.append(", ");
      out.append(std::to_string(t.cpus[i]));
    }
    out += "]";
  }
  return out + "}";
}

}  // namespace

std::string describe(const DaemonConfig& c) {
  std::string out;
  const auto line = [&out](std::string_view key, const std::string& value) {
    out.append(key).append(": ").append(value).append("\n");
  };
  const auto num = [&line](std::string_view key, double v) { line(key, format_number(v)); };
  const auto flag = [&line](std::string_view key, bool v) { line(key, v ? "true" : "false"); };

  std::string origin("{lat_deg: ");
  origin.append(format_number(c.origin.lat_deg)).append(", lon_deg: ").append(format_number(c.origin.lon_deg));
  origin.append(", height_m: ").append(format_number(c.origin.height_m)).append("}");
  line("global_frame.origin", origin);
  line("trajectory.file", c.trajectory_file.string());
  line("trajectory.coordinates", c.trajectory_coordinates == TrajectoryCoordinates::kLatLon ? "lat_lon" : "global_xy");
  line("lidar.model", "VLP-16");
  line("lidar.calibration", c.lidar.calibration.string());
  line("lidar.mounting", format_mounting(c.lidar.robot_from_lidar));
  num("lidar.min_range_m", c.lidar.min_range_m);
  num("lidar.max_range_m", c.lidar.max_range_m);
  num("lidar.cut_azimuth_deg", c.lidar.cut_azimuth_deg);
  line("lidar.bind_address", c.lidar.bind_address);
  line("lidar.sensor_address", c.lidar.sensor_address);
  num("lidar.data_port", c.lidar.data_port);
  num("lidar.position_port", c.lidar.position_port);
  num("lidar.receive_buffer_bytes", c.lidar.receive_buffer_bytes);
  flag("lidar.share_ports", c.lidar.share_ports);
  const auto serial = [&](std::string_view name, const DaemonConfig::Serial& s) {
    line(std::string(name) + ".device", s.device);
    num(std::string(name) + ".baud", s.baud);
    num(std::string(name) + ".delay_s", s.delay_s);
    flag(std::string(name) + ".configure", s.configure);
    num(std::string(name) + ".rate_hz", s.rate_hz);
  };
  serial("gnss", c.gnss);
  line("gnss.antenna", format_vector(c.gnss_antenna_m));
  serial("imu", c.imu);
  num("imu.magnetic_declination_deg", c.magnetic_declination_deg);
  line("imu.mounting", format_mounting(Eigen::Isometry3d(c.robot_from_imu)));
  line("pose.source", std::string(to_string(c.pose_source)));
  num("pose.gnss_heading.min_speed_mps", c.gnss_heading.min_speed_mps);
  num("pose.gnss_heading.max_heading_acc_deg", c.gnss_heading.max_heading_acc_deg);
  num("pose.gnss_heading.baseline_yaw_deg", c.gnss_heading.baseline_yaw_deg);
  line("pose.gnss_heading.initial_heading_deg",
       c.gnss_heading.initial_heading_deg ? format_number(*c.gnss_heading.initial_heading_deg) : "none");
  line("pose.fixed", format_mounting(c.fixed_pose));
  line("pose.mode", c.pose_mode == PoseMode::kPerSweep ? "per_sweep" : "per_firing");
  num("pose.min_fix_type", c.gate.min_fix_type);
  flag("pose.require_gnss_fix_ok", c.gate.require_gnss_fix_ok);
  num("pose.max_h_acc_m", c.gate.max_h_acc_m);
  flag("pose.require_rtk_fixed", c.gate.require_rtk_fixed);
  num("pose.max_extrapolation_s", static_cast<double>(c.gate.max_extrapolation_ns) * 1e-9);
  num("pose.max_gap_s", static_cast<double>(c.gate.max_gap_ns) * 1e-9);
  num("pose.buffer_samples", static_cast<double>(c.pose_capacity));
  line("roi.shape", c.roi.shape == RoiShape::kRectangular ? "rectangular" : "circular");
  num("roi.circle_diameter_m", c.roi.circle_diameter_m);
  num("roi.rect_height_m", c.roi.rect_height_m);
  num("roi.rect_width_m", c.roi.rect_width_m);
  num("roi.spacing_ratio", c.roi.spacing_ratio);
  num("roi.look_ahead_m", c.roi.look_ahead_m);
  num("roi.z_min_m", c.roi.z_min_m);
  num("roi.z_max_m", c.roi.z_max_m);
  num("roi.speed_scaling.look_ahead_s", c.roi.look_ahead_per_mps_s);
  num("roi.speed_scaling.width_s", c.roi.width_per_mps_s);
  num("roi.speed_scaling.max_speed_mps", c.roi.max_speed_mps);
  line("lcm.url", c.lcm.url);
  line("lcm.channels.points", c.lcm.points);
  line("lcm.channels.pose", c.lcm.pose);
  line("lcm.channels.roi", c.lcm.roi);
  line("lcm.channels.status", c.lcm.status);
  line("lcm.channels.trajectory", c.lcm.trajectory);
  line("lcm.channels.pose_input", c.lcm.pose_input);
  num("buffers.lidar_packets", static_cast<double>(c.buffers.lidar_packets));
  num("buffers.serial_chunks", static_cast<double>(c.buffers.serial_chunks));
  num("buffers.sweeps", static_cast<double>(c.buffers.sweeps));
  num("buffers.max_points_per_sweep", static_cast<double>(c.buffers.max_points_per_sweep));
  num("time.max_gnss_offset_s", c.time.max_gnss_offset_s);
  line("logging.level", c.logging.level);
  num("logging.warning_interval_s", c.logging.warning_interval_s);
  flag("realtime.lock_memory", c.realtime.lock_memory);
  line("realtime.threads.lidar", format_thread(c.realtime.lidar));
  line("realtime.threads.gnss", format_thread(c.realtime.gnss));
  line("realtime.threads.imu", format_thread(c.realtime.imu));
  line("realtime.threads.processing", format_thread(c.realtime.processing));
  line("realtime.threads.publisher", format_thread(c.realtime.publisher));
  return out;
}

DaemonConfig load_daemon_config(const std::filesystem::path& file) {
  return parse_daemon_config(config::read_text_file(file), file);
}

}  // namespace trajroi::daemon
