#include "trajroi/vlp16/decoder.hpp"

#include <cmath>
#include <numbers>

namespace trajroi::vlp16 {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kBlockDuration_us = 2.0 * kFiringCycle_us;  // two firings: 110.592

// The azimuth advance from `from` to `to`, hundredths of a degree, across the 0/360 wrap.
std::uint32_t azimuth_gap(std::uint16_t from, std::uint16_t to) noexcept {
  return (static_cast<std::uint32_t>(to) + kAzimuthLimit - from) % kAzimuthLimit;
}

}  // namespace

Calibration Calibration::vlp16_default() {
  static constexpr double kVerticalDeg[kLasers] = {-15, 1, -13, 3, -11, 5, -9, 7,
                                                   -7,  9, -5,  11, -3, 13, -1, 15};
  static constexpr double kVerticalOffset_mm[kLasers] = {11.2, -0.7, 9.7, -2.2, 8.1, -3.7, 6.6, -5.1,
                                                         5.1,  -6.6, 3.7, -8.1, 2.2, -9.7, 0.7, -11.2};
  Calibration c;
  for (std::size_t i = 0; i < kLasers; ++i) {
    c.lasers[i].vert_angle_rad = kVerticalDeg[i] * kDegToRad;
    c.lasers[i].vert_offset_m = kVerticalOffset_mm[i] / 1000.0;
  }
  return c;
}

PacketDecoder::PacketDecoder(const Calibration& calibration, DecodeOptions options)
    : options_(options), lasers_(calibration.lasers) {
  for (std::size_t i = 0; i < kLasers; ++i) {
    cos_vert_[i] = std::cos(lasers_[i].vert_angle_rad);
    sin_vert_[i] = std::sin(lasers_[i].vert_angle_rad);
  }
}

PacketDecoder::Result PacketDecoder::decode(std::span<const std::uint8_t> packet,
                                            std::vector<Point>& out) const {
  Result result;
  const bool dual = return_mode_byte(packet) == static_cast<std::uint8_t>(ReturnMode::kDual);
  const std::size_t step = dual ? 2 : 1;  // blocks per firing pair
  const ReturnType single_type =
      return_mode_byte(packet) == static_cast<std::uint8_t>(ReturnMode::kLast) ? ReturnType::kLast
                                                                               : ReturnType::kStrongest;

  auto emit = [&](std::size_t block, std::size_t channel, double azimuth_cdeg, double time_us,
                  ReturnType type) {
    const std::uint16_t raw = channel_distance(packet, block, channel);
    if (raw == 0) {
      ++result.no_return;
      return;
    }
    const std::size_t laser = channel % kLasers;
    const LaserCalibration& cal = lasers_[laser];
    const double range = static_cast<double>(raw) * kDistanceUnit_m + cal.dist_correction_m;
    if (!(range >= options_.min_range_m && range <= options_.max_range_m)) {
      ++result.out_of_range;
      return;
    }
    const double azimuth = azimuth_cdeg / 100.0 * kDegToRad + cal.rot_correction_rad;
    const double horizontal = range * cos_vert_[laser];
    Point p{};
    p.x = static_cast<float>(horizontal * std::cos(azimuth));
    p.y = static_cast<float>(-horizontal * std::sin(azimuth));
    p.z = static_cast<float>(range * sin_vert_[laser] + cal.vert_offset_m);
    p.distance_m = static_cast<float>(range);
    p.azimuth_deg = static_cast<float>(azimuth_cdeg / 100.0);
    p.time_offset_ns = static_cast<std::uint32_t>(std::lround(time_us * 1000.0));
    p.intensity = channel_reflectivity(packet, block, channel);
    p.laser = static_cast<std::uint8_t>(laser);
    p.return_type = type;
    out.push_back(p);
    ++result.points;
  };

  for (std::size_t block = 0; block < kBlocks; block += step) {
    const std::uint16_t azimuth = block_azimuth(packet, block);
    // Azimuth advance over this block's 110.592 µs: towards the next firing's block, or for
    // the packet's last firing, the advance over the previous one.
    const std::uint32_t gap = block + step < kBlocks
                                  ? azimuth_gap(azimuth, block_azimuth(packet, block + step))
                                  : azimuth_gap(block_azimuth(packet, block - step), azimuth);
    const double block_time_us = static_cast<double>(block / step) * kBlockDuration_us;
    for (std::size_t channel = 0; channel < kFiringsPerBlock * kLasers; ++channel) {
      const std::size_t firing = channel / kLasers;
      const double in_block_us = static_cast<double>(firing) * kFiringCycle_us +
                                 static_cast<double>(channel % kLasers) * kLaserPeriod_us;
      double azimuth_cdeg = azimuth + static_cast<double>(gap) * (in_block_us / kBlockDuration_us);
      if (azimuth_cdeg >= kAzimuthLimit) azimuth_cdeg -= kAzimuthLimit;
      const double time_us = block_time_us + in_block_us;
      if (!dual) {
        emit(block, channel, azimuth_cdeg, time_us, single_type);
        continue;
      }
      const std::uint16_t last = channel_distance(packet, block, channel);
      const std::uint16_t strongest = channel_distance(packet, block + 1, channel);
      if (last == strongest) {
        emit(block, channel, azimuth_cdeg, time_us, ReturnType::kBoth);
        if (strongest == 0) ++result.no_return;  // the pair's second (empty) return
        continue;
      }
      emit(block, channel, azimuth_cdeg, time_us, ReturnType::kLast);
      emit(block + 1, channel, azimuth_cdeg, time_us, ReturnType::kStrongest);
    }
  }
  return result;
}

}  // namespace trajroi::vlp16
