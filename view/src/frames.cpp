#include "trajroi/view/frames.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace trajroi::view {
namespace {

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

void pad4(std::vector<std::uint8_t>& out, std::uint8_t fill) {
  while (out.size() % 4 != 0)
    out.push_back(fill);
}

template <typename T>
std::span<const std::uint8_t> bytes_of(const std::vector<T>& v) {
  return {reinterpret_cast<const std::uint8_t*>(v.data()), v.size() * sizeof(T)};
}

// x, y, z interleaved: what a three.js position attribute takes as it is.
std::vector<float> interleave(std::span<const float> x, std::span<const float> y, std::span<const float> z) {
  const std::size_t n = std::min({x.size(), y.size(), z.size()});
  std::vector<float> xyz(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    xyz[3 * i] = x[i];
    xyz[3 * i + 1] = y[i];
    xyz[3 * i + 2] = z[i];
  }
  return xyz;
}

static_assert(std::endian::native == std::endian::little, "the page reads the arrays as little-endian");

}  // namespace

void Json::separate() {
  if (!first_) out_ += ',';
  first_ = false;
}

Json& Json::begin_object() {
  separate();
  out_ += '{';
  first_ = true;
  return *this;
}

Json& Json::end_object() {
  out_ += '}';
  first_ = false;
  return *this;
}

Json& Json::begin_array(std::string_view k) {
  if (!k.empty()) key(k);
  separate();
  out_ += '[';
  first_ = true;
  return *this;
}

Json& Json::end_array() {
  out_ += ']';
  first_ = false;
  return *this;
}

Json& Json::key(std::string_view k) {
  value(k);
  out_ += ':';
  first_ = true;  // the value follows without a comma
  return *this;
}

Json& Json::value(double v) {
  separate();
  if (!std::isfinite(v)) {
    out_ += "null";
    return *this;
  }
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.9g", v);
  out_.append(buf, static_cast<std::size_t>(n));
  return *this;
}

Json& Json::value(std::int64_t v) {
  separate();
  out_ += std::to_string(v);
  return *this;
}

Json& Json::value(bool v) {
  separate();
  out_ += v ? "true" : "false";
  return *this;
}

Json& Json::value(std::string_view v) {
  separate();
  out_ += '"';
  for (const char c : v) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out_ += '\\';
      out_ += c;
    } else if (u < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      out_ += buf;
    } else {
      out_ += c;
    }
  }
  out_ += '"';
  return *this;
}

std::vector<std::uint8_t> encode_frame(FrameKind kind, std::string_view json,
                                       std::span<const std::span<const std::uint8_t>> arrays) {
  std::size_t size = 12 + json.size() + 3;
  for (const auto& a : arrays)
    size += a.size() + 3;
  std::vector<std::uint8_t> out;
  out.reserve(size);
  put_u32(out, kFrameMagic);
  put_u32(out, static_cast<std::uint32_t>(kind));
  const std::size_t padded = (json.size() + 3) / 4 * 4;
  put_u32(out, static_cast<std::uint32_t>(padded));
  out.insert(out.end(), json.begin(), json.end());
  pad4(out, ' ');
  for (const auto& a : arrays) {
    out.insert(out.end(), a.begin(), a.end());
    pad4(out, 0);
  }
  return out;
}

std::vector<std::uint8_t> encode_sweep(const SweepView& s) {
  const std::vector<float> xyz = interleave(s.x, s.y, s.z);
  const std::size_t n = xyz.size() / 3;
  Json j;
  j.begin_object()
      .field("sweep", s.sweep_index)
      .field("end_ns", s.sweep_end_ns)
      .field("trajectory_id", std::int64_t{s.trajectory_id})
      .field("partial", s.partial)
      .field("points_in", std::int64_t{s.points_in})
      .field("n", static_cast<std::int64_t>(n));
  j.begin_array("sensors");
  for (const std::string& name : s.sensor_names)
    j.value(std::string_view(name));
  j.end_array();
  j.key("pose").begin_object();
  j.field("valid", s.pose_valid).field("x", s.robot_x_m).field("y", s.robot_y_m).field("z", s.robot_z_m);
  j.field("yaw", s.yaw_rad).end_object();
  if (s.have_roi) {
    const RoiChainView& r = s.roi;
    j.key("roi").begin_object();
    j.field("shape", std::string_view(r.circular ? "circular" : "rectangular"));
    j.field("r", r.radius_m).field("a", r.height_m).field("b", r.width_m);
    j.begin_array("centres");
    const std::size_t m = std::min({r.cx.size(), r.cy.size(), r.theta_rad.size()});
    for (std::size_t i = 0; i < m; ++i)
      j.begin_array().value(r.cx[i]).value(r.cy[i]).value(r.theta_rad[i]).end_array();
    j.end_array().end_object();
  }
  j.end_object();
  const std::span<const std::uint8_t> intensity = s.intensity.first(std::min(n, s.intensity.size()));
  std::vector<std::uint8_t> shades(intensity.begin(), intensity.end());
  shades.resize(n, 0);
  const std::span<const std::uint8_t> sensor = s.sensor.first(std::min(n, s.sensor.size()));
  std::vector<std::uint8_t> sensors(sensor.begin(), sensor.end());
  sensors.resize(n, 0);
  const std::span<const std::uint8_t> arrays[] = {bytes_of(xyz), bytes_of(shades), bytes_of(sensors)};
  return encode_frame(FrameKind::kSweep, j.text(), arrays);
}

std::vector<std::uint8_t> encode_raw_points(std::int64_t sweep_index, std::span<const float> x,
                                            std::span<const float> y, std::span<const float> z) {
  const std::vector<float> xyz = interleave(x, y, z);
  Json j;
  j.begin_object().field("sweep", sweep_index).field("n", static_cast<std::int64_t>(xyz.size() / 3)).end_object();
  const std::span<const std::uint8_t> arrays[] = {bytes_of(xyz)};
  return encode_frame(FrameKind::kRawPoints, j.text(), arrays);
}

std::vector<std::uint8_t> encode_trajectory(std::int32_t id, std::span<const double> x_m, std::span<const double> y_m) {
  const std::size_t n = std::min(x_m.size(), y_m.size());
  std::vector<float> xy(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    xy[2 * i] = static_cast<float>(x_m[i]);
    xy[2 * i + 1] = static_cast<float>(y_m[i]);
  }
  Json j;
  j.begin_object().field("id", std::int64_t{id}).field("n", static_cast<std::int64_t>(n)).end_object();
  const std::span<const std::uint8_t> arrays[] = {bytes_of(xy)};
  return encode_frame(FrameKind::kTrajectory, j.text(), arrays);
}

}  // namespace trajroi::view
