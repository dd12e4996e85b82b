// The built-in geometry of each model, from its manual's laser table ("Laser angles" /
// "Vertical angles and offsets"), in firing order (laser id 0, 1, …).
#include <numbers>

#include "trajroi/vlp16/decoder.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Puck Hi-Res: ±10° in 1.33° steps, and its vertical offset corrections (mm).
constexpr double kHiResVerticalDeg[16] = {-10.00, 0.67, -8.67, 2.00, -7.33, 3.33, -6.00, 4.67,
                                          -4.67,  6.00, -3.33, 7.33, -2.00, 8.67, -0.67, 10.00};
constexpr double kHiResVerticalOffset_mm[16] = {7.4, -0.9, 6.5, -1.8, 5.5, -2.7, 4.6, -3.7,
                                                3.7, -4.6, 2.7, -5.5, 1.8, -6.5, 0.9, -7.4};

// VLP-32C: vertical angles and azimuth offsets. The offsets as the velodyne/nebula calibration
// files carry them (rot_correction: θ = azimuth − rot_correction).
constexpr double kVlp32cVerticalDeg[32] = {-25.0,  -1.0,  -1.667, -15.639, -11.31, 0.0,   -0.667, -8.843,
                                           -7.254, 0.333, -0.333, -6.148,  -5.333, 1.333, 0.667,  -4.0,
                                           -4.667, 1.667, 1.0,    -3.667,  -3.333, 3.333, 2.333,  -2.667,
                                           -3.0,   7.0,   4.667,  -2.333,  -2.0,   15.0,  10.333, -1.333};
constexpr double kVlp32cRotationDeg[32] = {-1.4, 4.2,  -1.4, 1.4,  -1.4, 1.4,  -4.2, 1.4,  -1.4, 4.2,  -1.4,
                                           1.4,  -4.2, 1.4,  -4.2, 1.4,  -1.4, 4.2,  -1.4, 4.2,  -4.2, 1.4,
                                           -1.4, 1.4,  -1.4, 1.4,  -1.4, 4.2,  -4.2, 1.4,  -1.4, 1.4};

// HDL-32E: −30.67° … +10.67° in 1.33° steps, the lower and upper halves interleaved.
constexpr double kHdl32eVerticalDeg[32] = {-30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33,
                                           -25.33, -4.00, -24.00, -2.67, -22.67, -1.33, -21.33, 0.00,
                                           -20.00, 1.33,  -18.67, 2.67,  -17.33, 4.00,  -16.00, 5.33,
                                           -14.67, 6.67,  -13.33, 8.00,  -12.00, 9.33,  -10.67, 10.67};

}  // namespace

Calibration Calibration::for_model(Model model) {
  Calibration c;
  switch (model) {
    case Model::kVlp16:
      return vlp16_default();
    case Model::kPuckHiRes:
      for (std::size_t i = 0; i < 16; ++i) {
        c.lasers[i].vert_angle_rad = kHiResVerticalDeg[i] * kDegToRad;
        c.lasers[i].vert_offset_m = kHiResVerticalOffset_mm[i] / 1000.0;
      }
      return c;
    case Model::kVlp32c:
      c.laser_count = 32;
      for (std::size_t i = 0; i < 32; ++i) {
        c.lasers[i].vert_angle_rad = kVlp32cVerticalDeg[i] * kDegToRad;
        c.lasers[i].rot_correction_rad = kVlp32cRotationDeg[i] * kDegToRad;
      }
      return c;
    case Model::kHdl32e:
      c.laser_count = 32;
      for (std::size_t i = 0; i < 32; ++i)
        c.lasers[i].vert_angle_rad = kHdl32eVerticalDeg[i] * kDegToRad;
      return c;
  }
  return vlp16_default();
}

}  // namespace trajroi::vlp16
