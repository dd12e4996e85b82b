#pragma once

// What `trajroi view` sends its page: binary WebSocket messages, one envelope for all
// (little-endian): the bytes "TRV1", a uint32 kind, a uint32 length of a JSON header (padded
// with spaces to a multiple of 4), the header, then the kind's arrays, each starting at a
// multiple of 4 bytes. Points travel as arrays (Float32Array, Uint8Array on the page, no copy),
// never in the JSON. Pure: numbers in, bytes out.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace trajroi::view {

enum class FrameKind : std::uint32_t {
  kSweep = 1,       // header: sweep, sensors, pose, ROI chain; arrays: float32 xyz[3n], uint8 intensity[n],
                    // uint8 sensor[n]
  kRawPoints = 2,   // header: sweep index; arrays: float32 xyz[3n] (decoded points before the ROI)
  kTrajectory = 3,  // header: id; arrays: float32 xy[2n]
  kStatus = 4,      // header only: the status in words and figures
  kPose = 5,        // header only: the newest pose, valid or not (a withheld sweep's too)
};
inline constexpr std::size_t kFrameKinds = 5;
inline constexpr std::uint32_t kFrameMagic = 0x31565254;  // "TRV1" as little-endian bytes

// A small JSON writer: objects, arrays, numbers (NaN and infinities as null), strings escaped.
class Json {
 public:
  Json& begin_object();
  Json& end_object();
  Json& begin_array(std::string_view key = {});
  Json& end_array();
  Json& key(std::string_view k);
  Json& value(double v);
  Json& value(std::int64_t v);
  Json& value(bool v);
  Json& value(std::string_view v);
  template <typename T>
  Json& field(std::string_view k, T v) {
    return key(k).value(v);
  }
  [[nodiscard]] const std::string& text() const noexcept { return out_; }

 private:
  void separate();
  std::string out_;
  bool first_ = true;  // no comma before the next element
};

struct RoiChainView {
  bool circular = true;
  double radius_m = 0.0, height_m = 0.0, width_m = 0.0;
  std::span<const double> cx, cy, theta_rad;  // centres, global frame
};

struct SweepView {
  std::int64_t sweep_index = 0;
  std::int64_t sweep_end_ns = 0;  // host CLOCK_MONOTONIC: the last firing
  std::int32_t trajectory_id = 0;
  bool partial = false;
  std::int32_t points_in = 0;
  double robot_x_m = 0.0, robot_y_m = 0.0, robot_z_m = 0.0, yaw_rad = 0.0;
  bool pose_valid = false;
  RoiChainView roi;
  bool have_roi = false;  // false: no roi_t of this sweep came
  std::span<const float> x, y, z;
  std::span<const std::uint8_t> intensity;
  // The sensor of each point (points_t.sensor) and the sensors' names; empty: one LiDAR.
  std::span<const std::uint8_t> sensor;
  std::span<const std::string> sensor_names;
};

// The envelope around `json` and `arrays` (each padded to 4 bytes).
[[nodiscard]] std::vector<std::uint8_t> encode_frame(FrameKind kind, std::string_view json,
                                                     std::span<const std::span<const std::uint8_t>> arrays = {});

[[nodiscard]] std::vector<std::uint8_t> encode_sweep(const SweepView& sweep);
[[nodiscard]] std::vector<std::uint8_t> encode_raw_points(std::int64_t sweep_index, std::span<const float> x,
                                                          std::span<const float> y, std::span<const float> z);
[[nodiscard]] std::vector<std::uint8_t> encode_trajectory(std::int32_t id, std::span<const double> x_m,
                                                          std::span<const double> y_m);

}  // namespace trajroi::view
