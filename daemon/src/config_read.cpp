#include "config_read.hpp"

#include <arpa/inet.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "trajroi/pose/attitude.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::daemon::config_read {
namespace {
constexpr double kDegToRad = std::numbers::pi / 180.0;
}  // namespace

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

std::string ipv4(MapReader& m, std::string_view key, const std::string& fallback, bool allow_empty) {
  std::string text = m.text(key, fallback);
  in_addr parsed{};
  m.require((allow_empty && text.empty()) || inet_pton(AF_INET, text.c_str(), &parsed) == 1, key,
            "must be a dotted IPv4 address");
  return text;
}

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

std::string format_number(double v) {
  if (std::isinf(v)) return "none";  // an absent limit
  if (v == 0.0) v = 0.0;             // not "-0"
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

// Appended piecewise: GCC 12's -Wrestrict misfires on "[" + std::string.
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

}  // namespace trajroi::daemon::config_read
