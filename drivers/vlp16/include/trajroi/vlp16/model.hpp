#pragma once

// The Velodyne models trajroi decodes. Their data packets share the VLP-16's layout (1206
// bytes: 12 blocks of a flag, an azimuth and 32 channels of distance and reflectivity, a
// top-of-hour timestamp, the return mode and the product id); they differ in how a block's
// 32 channels map to lasers and firing times, in the distance unit and in the lasers' angles:
//   VLP-16, Puck LITE (0x22), Puck Hi-Res (0x24): 16 lasers, a block holds two firing
//     sequences of 16 (2.304 µs apart, 55.296 µs per sequence); 2 mm.
//   VLP-32C (0x28): 32 lasers fired two at a time, 16 groups 2.304 µs apart, 55.296 µs per
//     sequence, one sequence per block; 4 mm.
//   HDL-32E (0x21): 32 lasers fired one at a time 1.152 µs apart, 46.08 µs per sequence,
//     one per block; 2 mm.
// (The manuals' "Firing timing" and "Laser angles" tables; the VLP-32C's is also nebula's.)
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace trajroi::vlp16 {

enum class Model : std::uint8_t { kVlp16, kPuckHiRes, kVlp32c, kHdl32e };
inline constexpr std::size_t kModelCount = 4;
inline constexpr std::size_t kMaxLasers = 32;

struct ModelSpec {
  Model model;
  std::string_view name;         // "VLP-32C"
  std::string_view config_name;  // "vlp32c", as lidar.model names it
  std::uint8_t product_id;
  std::size_t lasers;            // 16 or 32
  std::size_t lasers_per_group;  // fired together: 1, or 2 (VLP-32C)
  double laser_period_us;        // between two firing groups
  double firing_cycle_us;        // one firing sequence of every laser, recharge included
  std::int64_t laser_period_ns;  // the same in whole nanoseconds
  std::int64_t firing_cycle_ns;
  double distance_unit_m;

  // Firing sequences per block: 32 channels / lasers.
  [[nodiscard]] constexpr std::size_t firings_per_block() const noexcept { return 32 / lasers; }
  [[nodiscard]] constexpr double block_duration_us() const noexcept {
    return static_cast<double>(firings_per_block()) * firing_cycle_us;
  }
  [[nodiscard]] constexpr std::int64_t block_duration_ns() const noexcept {
    return static_cast<std::int64_t>(firings_per_block()) * firing_cycle_ns;
  }
  // Channel 0 … 31 of a block: its laser, and its firing time after the block's first (as a
  // fraction of the block's duration: the weight of the azimuth advance it takes).
  [[nodiscard]] constexpr std::size_t laser_of(std::size_t channel) const noexcept { return channel % lasers; }
  [[nodiscard]] constexpr std::int64_t channel_time_ns(std::size_t channel) const noexcept {
    return static_cast<std::int64_t>(channel / lasers) * firing_cycle_ns +
           static_cast<std::int64_t>(channel % lasers / lasers_per_group) * laser_period_ns;
  }
  [[nodiscard]] constexpr double azimuth_fraction(std::size_t channel) const noexcept {
    return (static_cast<double>(channel / lasers) * firing_cycle_us +
            static_cast<double>(channel % lasers / lasers_per_group) * laser_period_us) /
           block_duration_us();
  }
  // One packet's duration (12 blocks; in dual mode two blocks per firing).
  [[nodiscard]] constexpr double packet_period_us(bool dual) const noexcept {
    return 12.0 * block_duration_us() / (dual ? 2.0 : 1.0);
  }
};

[[nodiscard]] const ModelSpec& spec(Model model) noexcept;
[[nodiscard]] inline std::string_view to_string(Model model) noexcept {
  return spec(model).name;
}
// The model a product id byte names without doubt: 0x22, 0x24, 0x28 (0x21 is the HDL-32E's,
// but early VLP-16 firmware sent it too: ModelCheck decides it by timing); nullopt otherwise.
[[nodiscard]] std::optional<Model> unambiguous_model(std::uint8_t product_id) noexcept;
// lidar.model's names: vlp16, puck_lite (a VLP-16 in its packets), puck_hires, vlp32c, hdl32e.
[[nodiscard]] std::optional<Model> model_named(std::string_view name) noexcept;

}  // namespace trajroi::vlp16
