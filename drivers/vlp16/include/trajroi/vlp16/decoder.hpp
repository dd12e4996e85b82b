#pragma once

// Decoding of VLP-16 data packets into points in the sensor frame.
//
// Sensor frame (REP-103): x forward (azimuth 0), y left, z up, metres. The VLP-16 azimuth α
// grows clockwise seen from above, so with ω the laser's vertical angle and R the range:
//   x = R cos ω cos α,   y = −R cos ω sin α,   z = R sin ω + vertical offset.
// (The manual's own frame has y forward: x_m = R cos ω sin α, y_m = R cos ω cos α.)
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {

// One laser's geometry, as in the velodyne/nebula calibration files (angles in radians).
struct LaserCalibration {
  double vert_angle_rad = 0.0;        // ω
  double rot_correction_rad = 0.0;    // added to the azimuth
  double vert_offset_m = 0.0;         // added to z
  double horiz_offset_m = 0.0;        // not used by the VLP-16 (0 in its calibrations)
  double dist_correction_m = 0.0;     // added to the range
};

// Geometry of the 16 lasers, indexed by laser channel (firing order 0 … 15).
struct Calibration {
  std::array<LaserCalibration, kLasers> lasers{};
  // The VLP-16 manual's values: vertical angles −15, 1, −13, 3, … , −1, 15° in firing order,
  // and its vertical offset corrections (11.2 mm … −11.2 mm).
  [[nodiscard]] static Calibration vlp16_default();
};

// Which return of a dual-return pair a point is. In dual mode each firing fills a block pair:
// the even block holds the last return, the odd block the strongest (or, when the strongest
// is the last, the second strongest). Identical returns give one point, kBoth.
enum class ReturnType : std::uint8_t { kStrongest = 1, kLast = 2, kBoth = 3 };

struct Point {
  float x;                      // sensor frame, m
  float y;
  float z;
  float distance_m;             // corrected range
  float azimuth_deg;            // interpolated firing azimuth, [0, 360)
  std::uint32_t time_offset_ns; // after the packet's timestamp (first firing of block 0)
  std::uint8_t intensity;       // calibrated reflectivity
  std::uint8_t laser;           // laser channel 0 … 15 (firing order)
  ReturnType return_type;
};

struct DecodeOptions {
  double min_range_m = 0.0;  // inclusive; ranges outside are dropped (and counted)
  double max_range_m = std::numeric_limits<double>::infinity();
};

class PacketDecoder {
 public:
  explicit PacketDecoder(const Calibration& calibration, DecodeOptions options = {});

  struct Result {
    std::size_t points = 0;        // appended to `out`
    std::size_t no_return = 0;     // zero distance
    std::size_t out_of_range = 0;  // outside [min_range, max_range]
  };

  // Appends the points of one packet that validate_data_packet() accepted. Never reads
  // outside the packet; allocates only if `out` must grow.
  Result decode(std::span<const std::uint8_t> packet, std::vector<Point>& out) const;

 private:
  DecodeOptions options_;
  std::array<LaserCalibration, kLasers> lasers_;
  std::array<double, kLasers> cos_vert_;
  std::array<double, kLasers> sin_vert_;
};

}  // namespace trajroi::vlp16
