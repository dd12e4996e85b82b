// The configuration keys of the global frame, the trajectory, the LiDAR, the GNSS receiver and
// the IMU (see config_keys.hpp).
#include <sys/stat.h>

#include <cmath>
#include <stdexcept>

#include "config_key_makers.hpp"
#include "trajroi/config/origin.hpp"
#include "trajroi/corrections/corrections_url.hpp"
#include "trajroi/serial/serial_port_source.hpp"

namespace trajroi::daemon::config_keys_detail {
namespace {

// The keys of one serial port (gnss or imu).
void add_serial_keys(std::vector<ConfigKey>& keys, DaemonConfig::Serial DaemonConfig::*port_of, bool gnss) {
  const auto at = [port_of](DaemonConfig& c) -> DaemonConfig::Serial& { return c.*port_of; };
  const auto of = [port_of](const DaemonConfig& c) -> const DaemonConfig::Serial& { return c.*port_of; };
  keys.push_back(
      {gnss ? "gnss.device" : "imu.device", "path",
       gnss ? "e.g. /dev/ttyACM0 or a udev link /dev/gnss; empty: no GNSS" : "e.g. /dev/ttyUSB0; empty: no IMU", false,
       [at](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
         DaemonConfig::Serial& s = at(c);
         s.device = m.text(k, s.device);
         // A device that does not exist yet is no configuration error (a USB receiver
         // can appear after the daemon starts: a run-time fault, said and retried); one
         // that exists must be a terminal or serial device.
         struct stat st {};
         m.require(s.device.empty() || ::stat(s.device.c_str(), &st) != 0 || S_ISCHR(st.st_mode), k,
                   "exists but is not a character device (a serial port or pseudo-terminal)");
       },
       [of](const DaemonConfig& c) { return of(c).device; }});
  keys.push_back({gnss ? "gnss.baud" : "imu.baud", "integer, a standard rate",
                  "the port's baud rate (a wrong rate shows as bytes that frame nothing)", false,
                  [at](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
                    DaemonConfig::Serial& s = at(c);
                    s.baud = static_cast<int>(m.integer(k, s.baud));
                    m.require(serial::is_supported_baud(s.baud), k, "must be one of " + serial::supported_bauds_text());
                  },
                  [of](const DaemonConfig& c) { return format_number(of(c).baud); }});
  keys.push_back({gnss ? "gnss.delay_s" : "imu.delay_s", "number in [0, 1)",
                  gnss ? "epoch → receipt of its NAV-PVT (latency + transmission; e.g. 0.0325 for a 100-byte "
                         "NAV-PVT at 115200 baud after 25 ms)"
                       : "sample → receipt of its frame (e.g. 0.0043 at 115200 baud)",
                  false,
                  [at](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
                    DaemonConfig::Serial& s = at(c);
                    s.delay_s = m.number(k, s.delay_s);
                    m.require(s.delay_s >= 0.0 && s.delay_s < 1.0, k, "must be in [0, 1) s");
                  },
                  [of](const DaemonConfig& c) { return format_number(of(c).delay_s); }});
  keys.push_back({gnss ? "gnss.configure" : "imu.configure", "boolean",
                  gnss ? "true: each time the device opens, set the receiver's output: NAV-PVT (+ NAV-HPPOSLLH, + "
                         "NAV-RELPOSNED with pose.source gnss) at rate_hz, CFG-VALSET (F9) or CFG-RATE + CFG-MSG "
                         "(M8), each ACKed"
                       : "true: each time the device opens, write binary output register 75 (TimeStartup + "
                         "YawPitchRoll at rate_hz) and read it back",
                  false,
                  [at](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
                    at(c).configure = m.boolean(k, at(c).configure);
                  },
                  [of](const DaemonConfig& c) { return flag(of(c).configure); }});
  keys.push_back({gnss ? "gnss.rate_hz" : "imu.rate_hz", "number in (0, 800]",
                  gnss ? "the navigation rate configure: true sets" : "the output rate configure: true sets", false,
                  [at](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
                    DaemonConfig::Serial& s = at(c);
                    s.rate_hz = m.positive(k, s.rate_hz);
                    m.require(s.rate_hz <= 800.0, k, "must be at most 800 Hz");
                  },
                  [of](const DaemonConfig& c) { return format_number(of(c).rate_hz); }});
}

std::string_view coordinates_text(TrajectoryCoordinates t) {
  return t == TrajectoryCoordinates::kLatLon ? "lat_lon" : "global_xy";
}

}  // namespace

void add_sensor_keys(std::vector<ConfigKey>& k) {
  // ---- global_frame, trajectory
  k.push_back(
      {"global_frame.origin", "{lat_deg, lon_deg, height_m}",
       "WGS-84 degrees and ellipsoid height (m): the origin of the global ENU frame", true,
       [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
         const config::Origin o = config::read_origin(m.map(key));
         c.origin = pose::Geodetic{o.lat_deg, o.lon_deg, o.height_m};
       },
       [](const DaemonConfig& c) {
         std::string out("{lat_deg: ");
         out.append(format_number(c.origin.lat_deg)).append(", lon_deg: ").append(format_number(c.origin.lon_deg));
         out.append(", height_m: ").append(format_number(c.origin.height_m)).append("}");
         return out;
       }});
  k.push_back({"trajectory.file", "path",
               "CSV: one waypoint per line; a first line 'x,y' or 'lat,lon' says which (SIGHUP re-reads it)", true,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir& dir) {
                 c.trajectory_file = resolve(dir, m.text(key));
               },
               [](const DaemonConfig& c) { return c.trajectory_file.string(); }});
  k.push_back({"trajectory.coordinates", "global_xy | lat_lon",
               "without that first line: global_xy (global frame, m) or lat_lon (WGS-84 degrees)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.trajectory_coordinates =
                     m.choice(key, {"global_xy", "lat_lon"}, coordinates_text(c.trajectory_coordinates)) == "lat_lon"
                         ? TrajectoryCoordinates::kLatLon
                         : TrajectoryCoordinates::kGlobalXy;
               },
               [](const DaemonConfig& c) { return std::string(coordinates_text(c.trajectory_coordinates)); }});
  // ---- lidar
  k.push_back({"lidar.model", "auto | vlp16 | puck_lite | puck_hires | vlp32c | hdl32e",
               "auto: told from the packets' product id; a model: other models' packets are dropped and named", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 // "VLP-16": the one value before the other models (configurations written then).
                 c.lidar.model = m.choice(
                     key, {"auto", "vlp16", "puck_lite", "puck_hires", "vlp32c", "hdl32e", "VLP-16"}, c.lidar.model);
                 if (c.lidar.model == "VLP-16") c.lidar.model = "vlp16";
               },
               [](const DaemonConfig& c) { return c.lidar.model; }});
  k.push_back({"lidar.calibration", "path",
               "velodyne/nebula YAML or VeloView XML calibration (16 or 32 lasers) for lidar.model (auto: 16 lasers, "
               "a VLP-16); empty: the model's manual values",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir& dir) {
                 c.lidar.calibration = resolve(dir, m.text(key, c.lidar.calibration.string()));
               },
               [](const DaemonConfig& c) { return c.lidar.calibration.string(); }});
  k.push_back({"lidar.mounting", "{xyz: [x, y, z], roll_deg, pitch_deg, yaw_deg}",
               "robot_from_lidar, e.g. {xyz: [0.1, 0, 0.7]}", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 if (m.has(key)) c.lidar.robot_from_lidar = read_mounting(m.map(key));
               },
               [](const DaemonConfig& c) { return format_mounting(c.lidar.robot_from_lidar); }});
  k.push_back(real_key(
      "lidar.min_range_m", "number ≥ 0", "returns nearer than this are dropped (e.g. 0.5: the robot itself)",
      Sign::kNonNegative, [](auto& c) -> auto& { return c.lidar.min_range_m; }));
  k.push_back(real_key(
      "lidar.max_range_m", "number > min_range_m", "returns farther than this are dropped (the VLP-16 reaches 100 m)",
      Sign::kPositive, [](auto& c) -> auto& { return c.lidar.max_range_m; }));
  k.push_back(
      {"lidar.cut_azimuth_deg", "number in [0, 360)", "a sweep starts at this azimuth (0: straight ahead)", false,
       [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
         c.lidar.cut_azimuth_deg = m.number(key, c.lidar.cut_azimuth_deg);
         m.require(c.lidar.cut_azimuth_deg >= 0.0 && c.lidar.cut_azimuth_deg < 360.0, key, "must be in [0, 360)");
       },
       [](const DaemonConfig& c) { return format_number(c.lidar.cut_azimuth_deg); }});
  k.push_back({"lidar.bind_address", "IPv4 address", "the address the UDP sockets bind to", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.lidar.bind_address = ipv4(m, key, c.lidar.bind_address, false);
               },
               [](const DaemonConfig& c) { return c.lidar.bind_address; }});
  k.push_back({"lidar.sensor_address", "IPv4 address or empty",
               "e.g. 192.168.1.201: datagrams from any other sender are dropped (counted as "
               "lidar.rejected_source); empty: any",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.lidar.sensor_address = ipv4(m, key, c.lidar.sensor_address, true);
                 m.require(c.lidar.sensor_address != "0.0.0.0", key, "must name one host (empty accepts any)");
               },
               [](const DaemonConfig& c) { return c.lidar.sensor_address; }});
  k.push_back({"lidar.data_port", "UDP port", "the data packets' port", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.lidar.data_port = port(m, key, c.lidar.data_port);
               },
               [](const DaemonConfig& c) { return format_number(c.lidar.data_port); }});
  k.push_back({"lidar.position_port", "UDP port", "the position packets' port (GPRMC, PPS status)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.lidar.position_port = port(m, key, c.lidar.position_port);
               },
               [](const DaemonConfig& c) { return format_number(c.lidar.position_port); }});
  k.push_back({"lidar.receive_buffer_bytes", "integer in [65536, 2³⁰]",
               "SO_RCVBUF asked for (past net.core.rmem_max where permitted; a capped buffer is warned)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.lidar.receive_buffer_bytes = static_cast<int>(count(
                     m, key, static_cast<std::size_t>(c.lidar.receive_buffer_bytes), 65536, std::size_t{1} << 30));
               },
               [](const DaemonConfig& c) { return format_number(c.lidar.receive_buffer_bytes); }});
  k.push_back(flag_key(
      "lidar.share_ports",
      "false: the ports are this daemon's alone (a second reader fails at start, naming the port); "
      "true: SO_REUSEADDR, for multicast",
      [](auto& c) -> auto& { return c.lidar.share_ports; }));
  // ---- lidar_merge (several LiDARs)
  k.push_back(real_key(
      "lidar_merge.max_wait_s", "number > 0",
      "after the first sensor's sweep of a window, the others' are waited for this long at most (input time)",
      Sign::kPositive, [](auto& c) -> auto& { return c.lidar_merge.max_wait_s; }));
  k.push_back(real_key(
      "lidar_merge.silent_s", "number > 0",
      "a sensor with no sweep for this long is silent: named in the log and the status, and not waited for",
      Sign::kPositive, [](auto& c) -> auto& { return c.lidar_merge.silent_s; }));
  k.push_back({"lidar_merge.publish", "merged | per_sensor",
               "merged: one points_t per window with every sensor's kept points; per_sensor: each sweep alone", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.lidar_merge.per_sensor =
                     m.choice(key, {"merged", "per_sensor"}, c.lidar_merge.per_sensor ? "per_sensor" : "merged") ==
                     "per_sensor";
               },
               [](const DaemonConfig& c) { return std::string(c.lidar_merge.per_sensor ? "per_sensor" : "merged"); }});
  // ---- gnss, imu
  add_serial_keys(k, &DaemonConfig::gnss, true);
  k.push_back({"gnss.antenna", "[x, y, z]",
               "the antenna's position in the robot frame, m (lever arm), e.g. [-0.2, 0, 0.9]", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 const Eigen::Vector3d& d = c.gnss_antenna_m;
                 const auto a = m.numbers(key, {d.x(), d.y(), d.z()});
                 c.gnss_antenna_m = Eigen::Vector3d(a[0], a[1], a[2]);
               },
               [](const DaemonConfig& c) { return format_vector(c.gnss_antenna_m); }});
  k.push_back({"gnss.corrections.url", "URL or \"\"",
               "RTK corrections written into the receiver through gnss.device: ntrip://user:password@host:port/MOUNT, "
               "tcp://host:port, udp://[address]:port, serial:///dev/ttyUSB1?baud=57600 (a radio), lcm://CHANNEL "
               "(rtcm_t); empty: none",
               false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.gnss_corrections.url = m.text(key, c.gnss_corrections.url);
                 if (c.gnss_corrections.url.empty()) return;
                 try {
                   (void)corrections::parse_corrections_url(c.gnss_corrections.url);
                 } catch (const std::invalid_argument& e) {
                   m.require(false, key, e.what());
                 }
               },
               [](const DaemonConfig& c) {
                 if (c.gnss_corrections.url.empty()) return std::string();
                 return corrections::parse_corrections_url(c.gnss_corrections.url).redacted();
               }});
  k.push_back(real_key(
      "gnss.corrections.gga_interval_s", "number ≥ 0",
      "NTRIP: the rover's position (GGA) sent to the caster this often, for VRS mountpoints (0: never)",
      Sign::kNonNegative, [](auto& c) -> auto& { return c.gnss_corrections.gga_interval_s; }));
  k.push_back(real_key(
      "gnss.corrections.stall_s", "number > 0", "no corrections byte for this long: the stream is lost (reconnect)",
      Sign::kPositive, [](auto& c) -> auto& { return c.gnss_corrections.stall_s; }));
  k.push_back(real_key(
      "gnss.max_correction_age_s", "number > 0",
      "the newest corrections frame written into the receiver longer ago than this is warned", Sign::kPositive,
      [](auto& c) -> auto& { return c.gnss_corrections.max_age_s; }));
  add_serial_keys(k, &DaemonConfig::imu, false);
  k.push_back({"imu.magnetic_declination_deg", "number in [-180, 180]",
               "added to the VN-100's magnetic heading, positive east", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 c.magnetic_declination_deg = m.number(key, c.magnetic_declination_deg);
                 m.require(std::abs(c.magnetic_declination_deg) <= 180.0, key, "must be in [-180, 180]");
               },
               [](const DaemonConfig& c) { return format_number(c.magnetic_declination_deg); }});
  k.push_back({"imu.mounting", "{roll_deg, pitch_deg, yaw_deg}", "robot_from_imu (its rotation)", false,
               [](MapReader& m, std::string_view key, DaemonConfig& c, const Dir&) {
                 if (m.has(key)) c.robot_from_imu = Eigen::Quaterniond(read_mounting(m.map(key)).linear());
               },
               [](const DaemonConfig& c) { return format_mounting(Eigen::Isometry3d(c.robot_from_imu)); }});
}

}  // namespace trajroi::daemon::config_keys_detail
