#include "trajroi/sim/scenario.hpp"

#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "trajroi/config/origin.hpp"
#include "trajroi/config/text_file.hpp"
#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/framing/utc.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::sim {
namespace {

using config::MapReader;

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kMaxVlp16Range_m = 65535 * vlp16::kDistanceUnit_m;

std::uint8_t reflectivity(MapReader& r, std::string_view key, std::uint8_t fallback) {
  const std::int64_t v = r.integer(key, fallback);
  r.require(v >= 0 && v <= 255, key, "must be 0 … 255");
  return static_cast<std::uint8_t>(v);
}

Eigen::Vector2d xy(MapReader& r, std::string_view key) {
  const auto v = r.numbers(key, 2);
  return {v[0], v[1]};
}

Mounting read_mounting(MapReader m) {
  Mounting mount;
  const auto xyz = m.numbers("xyz", 3);
  mount.xyz_m = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  m.require(mount.xyz_m.z() > 0.0, "xyz", "the sensor must be above the ground (z > 0)");
  mount.roll_rad = m.number("roll_deg", 0.0) * kDegToRad;
  mount.pitch_rad = m.number("pitch_deg", 0.0) * kDegToRad;
  mount.yaw_rad = m.number("yaw_deg", 0.0) * kDegToRad;
  m.finish();
  return mount;
}

WorldSpec read_world(MapReader w) {
  WorldSpec world;
  world.ground_reflectivity = reflectivity(w, "ground_reflectivity", 20);
  w.each("boxes", [&](MapReader& b) {
    Box box;
    box.name = b.text("name", "box");
    box.centre_m = xy(b, "centre");
    box.size_m = xy(b, "size");
    b.require(box.size_m.x() > 0.0 && box.size_m.y() > 0.0, "size", "both sides must be > 0");
    box.height_m = b.positive("height", 1.0);
    box.yaw_rad = b.number("yaw_deg", 0.0) * kDegToRad;
    box.reflectivity = reflectivity(b, "reflectivity", 50);
    world.boxes.push_back(box);
  });
  w.each("cylinders", [&](MapReader& c) {
    Cylinder cylinder;
    cylinder.name = c.text("name", "cylinder");
    cylinder.centre_m = xy(c, "centre");
    cylinder.radius_m = c.positive("radius", 0.3);
    cylinder.height_m = c.positive("height", 1.0);
    cylinder.reflectivity = reflectivity(c, "reflectivity", 50);
    world.cylinders.push_back(cylinder);
  });
  w.finish();
  return world;
}

PathSpec read_path(MapReader t) {
  PathSpec path;
  path.start_m = xy(t, "start");
  path.heading_rad = t.number("heading_deg") * kDegToRad;
  t.each("segments", [&](MapReader& s) {
    PathSegment segment;
    if (s.has("line")) {
      segment.kind = PathSegment::Kind::kLine;
      segment.length_m = s.positive("line", 0.0);
    } else if (s.has("arc")) {
      MapReader arc = s.map("arc");
      segment.kind = PathSegment::Kind::kArc;
      segment.radius_m = arc.positive("radius", 0.0);
      const double turn_deg = arc.number("turn_deg");
      arc.require(turn_deg != 0.0 && std::abs(turn_deg) <= 360.0, "turn_deg", "must be non-zero and within ±360");
      segment.turn_rad = turn_deg * kDegToRad;
      arc.finish();
    } else {
      s.fail("line", "each segment is either 'line: LENGTH_M' or 'arc: {radius, turn_deg}'");
    }
    path.segments.push_back(segment);
  });
  t.require(!path.segments.empty(), "segments",
            "needs at least one segment: a trajectory of one point has no direction to follow");
  t.finish();
  return path;
}

RobotSpec read_robot(MapReader r) {
  RobotSpec robot;
  robot.speed_mps = r.positive("speed_mps", 0.5);
  r.require(robot.speed_mps <= 30.0, "speed_mps", "must be at most 30 m/s");
  robot.wait_before_s = r.non_negative("wait_before_s", robot.wait_before_s);
  robot.wait_after_s = r.non_negative("wait_after_s", robot.wait_after_s);
  if (r.has("lidar_mount")) robot.lidar = read_mounting(r.map("lidar_mount"));
  if (r.has("gnss_antenna")) {
    const auto a = r.numbers("gnss_antenna", 3);
    robot.gnss_antenna_m = Eigen::Vector3d(a[0], a[1], a[2]);
    r.require(a[2] > 0.0, "gnss_antenna", "the antenna must be above the ground (z > 0)");
  }
  r.finish();
  return robot;
}

LidarSpec read_lidar(MapReader l) {
  LidarSpec lidar;
  lidar.rpm = l.number("rpm", lidar.rpm);
  l.require(lidar.rpm >= 300.0 && lidar.rpm <= 1200.0, "rpm", "must be 300 … 1200 (a VLP-16 spins at 5 … 20 Hz)");
  const std::string mode = l.choice("return_mode", {"strongest", "last", "dual"}, "strongest");
  lidar.return_mode = mode == "dual"   ? vlp16::ReturnMode::kDual
                      : mode == "last" ? vlp16::ReturnMode::kLast
                                       : vlp16::ReturnMode::kStrongest;
  lidar.min_range_m = l.non_negative("min_range_m", lidar.min_range_m);
  lidar.max_range_m = l.positive("max_range_m", lidar.max_range_m);
  l.require(lidar.max_range_m <= kMaxVlp16Range_m, "max_range_m",
            "must be at most 131.07 m (the packet's 16-bit range)");
  l.require(lidar.max_range_m > lidar.min_range_m, "max_range_m", "must be above min_range_m");
  lidar.range_noise_m = l.non_negative("range_noise_m", 0.0);
  lidar.start_azimuth_deg = l.number("start_azimuth_deg", 0.0);
  l.require(lidar.start_azimuth_deg >= 0.0 && lidar.start_azimuth_deg < 360.0, "start_azimuth_deg",
            "must be in [0, 360)");
  l.finish();
  return lidar;
}

GnssSpec read_gnss(MapReader g) {
  GnssSpec gnss;
  gnss.rate_hz = g.positive("rate_hz", gnss.rate_hz);
  g.require(gnss.rate_hz <= 25.0, "rate_hz", "must be at most 25 Hz");
  gnss.latency_s = g.non_negative("latency_s", gnss.latency_s);
  g.require(gnss.latency_s < 1.0, "latency_s", "must be below 1 s");
  gnss.baud = g.positive("baud", gnss.baud);
  g.require(gnss.baud / 10.0 >= static_cast<double>(kGnssEpochBytes) * gnss.rate_hz, "baud",
            "too slow for NAV-HPPOSLLH and NAV-PVT at this rate");
  gnss.noise_h_m = g.non_negative("noise_h_m", 0.0);
  gnss.noise_v_m = g.non_negative("noise_v_m", 0.0);
  gnss.correlation_s = g.positive("correlation_s", gnss.correlation_s);
  gnss.h_acc_m = g.positive("h_acc_m", gnss.h_acc_m);
  g.each("faults", [&](MapReader& f) {
    GnssFault fault;
    const std::string kind = f.choice("kind", {"lost", "no_rtk", "float"}, "lost");
    fault.kind = kind == "lost"    ? GnssFault::Kind::kLost
                 : kind == "float" ? GnssFault::Kind::kFloat
                                   : GnssFault::Kind::kNoRtk;
    fault.from_s = f.non_negative("from_s", 0.0);
    fault.to_s = f.number("to_s");
    f.require(fault.to_s > fault.from_s, "to_s", "must be after from_s");
    const double default_noise = fault.kind == GnssFault::Kind::kFloat ? 0.15 : 1.0;
    fault.noise_m = f.non_negative("noise_m", fault.kind == GnssFault::Kind::kLost ? 0.0 : default_noise);
    fault.h_acc_m = f.positive("h_acc_m", fault.kind == GnssFault::Kind::kLost ? 50.0 : 2.0 * default_noise);
    gnss.faults.push_back(fault);
  });
  g.finish();
  return gnss;
}

ImuSpec read_imu(MapReader i) {
  ImuSpec imu;
  const std::int64_t divisor = i.integer("rate_divisor", imu.rate_divisor);
  i.require(divisor >= 1 && divisor <= 800, "rate_divisor", "must be 1 … 800 (800 Hz / divisor)");
  imu.rate_divisor = static_cast<int>(divisor);
  imu.latency_s = i.non_negative("latency_s", 0.0);
  i.require(imu.latency_s < 1.0, "latency_s", "must be below 1 s");
  imu.baud = i.positive("baud", imu.baud);
  i.require(imu.baud / 10.0 >= static_cast<double>(kImuFrameBytes) * 800.0 / imu.rate_divisor, "baud",
            "too slow for this output rate");
  imu.angle_noise_deg = i.non_negative("angle_noise_deg", 0.0);
  imu.gyro_noise_rps = i.non_negative("gyro_noise_rps", 0.0);
  imu.accel_noise_mps2 = i.non_negative("accel_noise_mps2", 0.0);
  imu.heading_bias_deg = i.number("heading_bias_deg", 0.0);
  i.require(std::abs(imu.heading_bias_deg) <= 180.0, "heading_bias_deg", "must be within ±180");
  imu.magnetic_declination_deg = i.number("magnetic_declination_deg", 0.0);
  i.require(std::abs(imu.magnetic_declination_deg) <= 180.0, "magnetic_declination_deg", "must be within ±180");
  i.finish();
  return imu;
}

EvaluationSpec read_evaluation(MapReader e) {
  EvaluationSpec ev;
  ev.circle_diameter_m = e.positive("circle_diameter_m", ev.circle_diameter_m);
  ev.rect_height_m = e.positive("rect_height_m", ev.rect_height_m);
  ev.rect_width_m = e.positive("rect_width_m", ev.rect_width_m);
  ev.look_ahead_m = e.positive("look_ahead_m", ev.look_ahead_m);
  ev.corridor_width_m = e.positive("corridor_width_m", ev.corridor_width_m);
  ev.cuboid_length_m = e.positive("cuboid_length_m", ev.cuboid_length_m);
  ev.cuboid_width_m = e.positive("cuboid_width_m", ev.cuboid_width_m);
  ev.cuboid_height_m = e.positive("cuboid_height_m", ev.cuboid_height_m);
  e.each("keyframes", [&](MapReader& k) {
    Keyframe keyframe;
    keyframe.name = k.text("name");
    keyframe.position_m = xy(k, "position");
    keyframe.heading_rad = k.number("heading_rad");
    ev.keyframes.push_back(keyframe);
  });
  e.finish();
  return ev;
}

}  // namespace

Eigen::Isometry3d Mounting::robot_from_sensor() const {
  return roi::pose_from_xyz_rpy(xyz_m, roll_rad, pitch_rad, yaw_rad);
}

bool parse_utc_iso8601(std::string_view text, std::int64_t& utc_ns) {
  // YYYY-MM-DDTHH:MM:SS[.fff…]Z
  if (text.size() < 20 || text.back() != 'Z' || text[4] != '-' || text[7] != '-' || text[10] != 'T' ||
      text[13] != ':' || text[16] != ':') {
    return false;
  }
  auto number = [&](std::size_t at, std::size_t digits, int& out) {
    const auto [end, ec] = std::from_chars(text.data() + at, text.data() + at + digits, out);
    return ec == std::errc{} && end == text.data() + at + digits;
  };
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (!number(0, 4, year) || !number(5, 2, month) || !number(8, 2, day) || !number(11, 2, hour) ||
      !number(14, 2, minute) || !number(17, 2, second) || hour > 23 || minute > 59 || second > 59) {
    return false;
  }
  std::int64_t fraction_ns = 0;
  const std::string_view rest = text.substr(19, text.size() - 20);
  if (!rest.empty()) {
    if (rest[0] != '.' || rest.size() < 2 || rest.size() > 10) return false;
    std::int64_t scale = 100'000'000;
    for (std::size_t i = 1; i < rest.size(); ++i, scale /= 10) {
      if (rest[i] < '0' || rest[i] > '9') return false;
      fraction_ns += (rest[i] - '0') * scale;
    }
  }
  const std::chrono::year_month_day ymd{std::chrono::year{year}, std::chrono::month{static_cast<unsigned>(month)},
                                        std::chrono::day{static_cast<unsigned>(day)}};
  if (!utc_representable(ymd)) return false;
  utc_ns = utc_ns_from_civil(ymd, hour * 3600 + minute * 60 + second) + fraction_ns;
  return true;
}

Scenario parse_scenario(std::string_view yaml_text, const std::string& source) {
  MapReader root = MapReader::parse(yaml_text, source);
  Scenario s;
  s.name = root.text("name");
  root.require(!s.name.empty(), "name", "must not be empty");
  const std::int64_t seed = root.integer("seed", 1);
  root.require(seed >= 0, "seed", "must be >= 0");
  s.seed = static_cast<std::uint64_t>(seed);
  const std::string start = root.text("start_utc");
  root.require(parse_utc_iso8601(start, s.start_utc_ns), "start_utc", "must be a UTC time like 2024-05-14T09:00:00Z");
  root.require(s.start_utc_ns >= 315'964'800'000'000'000 && s.start_utc_ns < 3'471'292'800'000'000'000, "start_utc",
               "must be between 1980-01-06 (the GPS epoch) and 2079");
  const config::Origin origin = config::read_origin(root.map("origin"));
  s.origin = pose::Geodetic{origin.lat_deg, origin.lon_deg, origin.height_m};
  s.world = read_world(root.map("world"));
  s.path = read_path(root.map("trajectory"));
  s.robot = read_robot(root.map("robot", true));
  s.lidar = read_lidar(root.map("lidar", true));
  s.gnss = read_gnss(root.map("gnss", true));
  s.imu = read_imu(root.map("imu", true));
  s.evaluation = read_evaluation(root.map("evaluation", true));
  root.finish();
  return s;
}

Scenario load_scenario(const std::filesystem::path& path) {
  return parse_scenario(config::read_text_file(path), path.string());
}

}  // namespace trajroi::sim
