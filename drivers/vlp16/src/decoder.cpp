#include "trajroi/vlp16/decoder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace trajroi::vlp16 {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kCentidegToRad = kDegToRad / 100.0;
constexpr std::size_t kChannels = kFiringsPerBlock * kLasers;

// Up to this azimuth step between firings (5°; a VLP-16 at 20 Hz steps 0.8°) the in-block
// rotation δ ≤ 0.09 rad is turned into cos/sin by series, whose truncation error (δ⁷/5040 <
// 1e-11) is far below float resolution. Larger steps only occur in damaged data; they take
// the library cos/sin.
constexpr std::uint32_t kSeriesGapLimit_cdeg = 500;

struct CosSin {
  double c, s;
};

// cos and sin of a small angle by their Taylor series.
CosSin small_angle(double d) noexcept {
  const double d2 = d * d;
  return {1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0))), d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0)))};
}

}  // namespace

std::string_view to_string(ReturnType type) noexcept {
  switch (type) {
    case ReturnType::kStrongest:
      return "strongest";
    case ReturnType::kLast:
      return "last";
    case ReturnType::kBoth:
      return "both";
  }
  return "unknown";
}

Calibration Calibration::vlp16_default() {
  static constexpr double kVerticalDeg[kLasers] = {-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15};
  static constexpr double kVerticalOffset_mm[kLasers] = {11.2, -0.7, 9.7, -2.2, 8.1, -3.7, 6.6, -5.1,
                                                         5.1,  -6.6, 3.7, -8.1, 2.2, -9.7, 0.7, -11.2};
  Calibration c;
  for (std::size_t i = 0; i < kLasers; ++i) {
    c.lasers[i].vert_angle_rad = kVerticalDeg[i] * kDegToRad;
    c.lasers[i].vert_offset_m = kVerticalOffset_mm[i] / 1000.0;
  }
  return c;
}

std::array<std::uint8_t, kLasers> Calibration::rings() const {
  std::array<std::uint8_t, kLasers> order{};
  for (std::size_t i = 0; i < kLasers; ++i)
    order[i] = static_cast<std::uint8_t>(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint8_t a, std::uint8_t b) { return lasers[a].vert_angle_rad < lasers[b].vert_angle_rad; });
  std::array<std::uint8_t, kLasers> ring{};
  for (std::size_t rank = 0; rank < kLasers; ++rank)
    ring[order[rank]] = static_cast<std::uint8_t>(rank);
  return ring;
}

PacketDecoder::PacketDecoder(const Calibration& calibration, DecodeOptions options) : options_(options) {
  const auto rings = calibration.rings();
  for (std::size_t i = 0; i < kLasers; ++i) {
    const LaserCalibration& cal = calibration.lasers[i];
    lasers_[i] = Laser{std::cos(cal.vert_angle_rad),
                       std::sin(cal.vert_angle_rad),
                       std::cos(cal.rot_correction_rad),
                       std::sin(cal.rot_correction_rad),
                       cal.vert_offset_m,
                       cal.horiz_offset_m,
                       cal.dist_correction_m,
                       rings[i]};
    rotation_corrected_ = rotation_corrected_ || cal.rot_correction_rad != 0.0;
  }
  for (std::size_t channel = 0; channel < kChannels; ++channel) {
    azimuth_fraction_[channel] = azimuth_fraction(channel);
    const auto in_block_ns = static_cast<std::int64_t>(channel / kLasers) * kFiringCycle_ns +
                             static_cast<std::int64_t>(channel % kLasers) * kLaserPeriod_ns;
    for (std::size_t pair = 0; pair < kBlocks; ++pair) {
      time_ns_[pair][channel] =
          static_cast<std::uint32_t>(static_cast<std::int64_t>(pair) * kBlockDuration_ns + in_block_ns);
    }
  }
}

PacketDecoder::Result PacketDecoder::decode(std::span<const std::uint8_t> packet, std::vector<Point>& out) const {
  Result result;
  const std::uint8_t mode = return_mode_byte(packet);
  const bool dual = mode == static_cast<std::uint8_t>(ReturnMode::kDual);
  const std::size_t step = dual ? 2 : 1;  // blocks per firing
  const ReturnType single_type =
      mode == static_cast<std::uint8_t>(ReturnMode::kLast) ? ReturnType::kLast : ReturnType::kStrongest;
  if (out.capacity() - out.size() < kBlocks * kChannels) out.reserve(out.size() + kBlocks * kChannels * 64);

  for (std::size_t block = 0; block < kBlocks; block += step) {
    const std::uint16_t azimuth = block_azimuth(packet, block);
    // Azimuth advance over this block's 110.592 µs: towards the next firing's block, or for
    // the packet's last firing, the advance over the previous one.
    const std::uint32_t gap = block + step < kBlocks ? azimuth_gap(azimuth, block_azimuth(packet, block + step))
                                                     : azimuth_gap(block_azimuth(packet, block - step), azimuth);
    const double base_rad = static_cast<double>(azimuth) * kCentidegToRad;
    const double cos_base = std::cos(base_rad);
    const double sin_base = std::sin(base_rad);
    const double gap_rad = static_cast<double>(gap) * kCentidegToRad;
    const bool series = gap <= kSeriesGapLimit_cdeg;
    const auto& time_ns = time_ns_[block / step];

    for (std::size_t channel = 0; channel < kChannels; ++channel) {
      // The returns of this firing: one, or in dual mode the last (even block) and strongest.
      const std::uint16_t first_raw = channel_distance(packet, block, channel);
      std::uint16_t second_raw = 0;
      ReturnType first_type = single_type;
      if (dual) {
        second_raw = channel_distance(packet, block + 1, channel);
        if (second_raw == first_raw) {
          second_raw = 0;
          if (first_raw == 0) {
            result.no_return += 2;
            continue;
          }
          first_type = ReturnType::kBoth;
          ++result.merged_returns;
        } else {
          first_type = ReturnType::kLast;
          if (second_raw == 0) ++result.no_return;
        }
      }
      if (first_raw == 0) {
        ++result.no_return;
        if (second_raw == 0) continue;
      }

      const double fraction = azimuth_fraction_[channel];
      double cos_a, sin_a;
      if (series) {
        const CosSin d = small_angle(gap_rad * fraction);
        cos_a = cos_base * d.c - sin_base * d.s;
        sin_a = sin_base * d.c + cos_base * d.s;
      } else {
        const double a = base_rad + gap_rad * fraction;
        cos_a = std::cos(a);
        sin_a = std::sin(a);
      }
      double azimuth_cdeg = static_cast<double>(azimuth) + static_cast<double>(gap) * fraction;
      if (azimuth_cdeg >= kAzimuthLimit) azimuth_cdeg -= kAzimuthLimit;
      float azimuth_deg = static_cast<float>(azimuth_cdeg / 100.0);
      if (azimuth_deg >= 360.0f) azimuth_deg = 0.0f;  // 359.99999… rounds up in float

      const std::size_t laser_index = channel % kLasers;
      const Laser& laser = lasers_[laser_index];
      if (rotation_corrected_) {  // θ = azimuth − rot_correction
        const double c = cos_a * laser.cos_rot + sin_a * laser.sin_rot;
        sin_a = sin_a * laser.cos_rot - cos_a * laser.sin_rot;
        cos_a = c;
      }

      auto emit = [&](std::uint16_t raw, std::size_t from_block, ReturnType type) {
        const double range = static_cast<double>(raw) * kDistanceUnit_m + laser.dist_correction_m;
        if (!(range >= options_.min_range_m && range <= options_.max_range_m)) {
          ++result.out_of_range;
          return;
        }
        const double r_xy = range * laser.cos_vert - laser.vert_offset_m * laser.sin_vert;
        Point& p = out.emplace_back();
        p.x = static_cast<float>(r_xy * cos_a + laser.horiz_offset_m * sin_a);
        p.y = static_cast<float>(-r_xy * sin_a + laser.horiz_offset_m * cos_a);
        p.z = static_cast<float>(range * laser.sin_vert + laser.vert_offset_m * laser.cos_vert);
        p.distance_m = static_cast<float>(range);
        p.azimuth_deg = azimuth_deg;
        p.time_offset_ns = time_ns[channel];
        p.intensity = channel_reflectivity(packet, from_block, channel);
        p.laser = static_cast<std::uint8_t>(laser_index);
        p.ring = laser.ring;
        p.return_type = type;
        ++result.points;
      };
      if (first_raw != 0) emit(first_raw, block, first_type);
      if (second_raw != 0) emit(second_raw, block + 1, ReturnType::kStrongest);
    }
  }
  return result;
}

}  // namespace trajroi::vlp16
