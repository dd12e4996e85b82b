#pragma once

// Which sensor sends a packet stream, from its product id byte (model.hpp): 0x22 a VLP-16 or
// Puck LITE, 0x24 a Puck Hi-Res, 0x28 a VLP-32C. 0x21 is the HDL-32E's code, but early VLP-16
// firmware (2014) sent it too, so a 0x21 stream is told apart by its timing: a VLP-16 sends a
// packet every 12 × 110.592 µs = 1327.1 µs in single return mode (663.6 µs in dual), an
// HDL-32E every 12 × 46.08 µs = 553 µs (276.5 µs), each with an azimuth step per firing that
// means 4.5–21 rotations per second under its own timing. Any other id is rejected at once.
//
// With an expected model (lidar.model) the packets of any other model are rejected, and so
// are those of a second model in one stream (a sensor does not change model mid-run): both
// named in reason().
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "trajroi/vlp16/model.hpp"

namespace trajroi::vlp16 {

class ModelCheck {
 public:
  // Undecided packets in a row (their timing unusable: repeated, reordered or far apart)
  // before the stream is rejected; a caller holding undecided packets needs this many slots.
  static constexpr unsigned kMaxUndecided = 32;

  // `expected`: the only model taken (nullopt: any model trajroi decodes, the first one seen).
  explicit ModelCheck(std::optional<Model> expected = Model::kVlp16) noexcept : expected_(expected) {}

  enum class Verdict : std::uint8_t {
    kDecided,    // the packet is the stream's model(): decode it
    kUndecided,  // a 0x21 stream whose timing has not been seen yet: hold the packet
    kRejected,
  };

  // The verdict for a packet that validate_data_packet() accepted. A 0x21 stream's verdict,
  // once decided, sticks.
  Verdict check(std::span<const std::uint8_t> packet);
  // The stream's model: the first decided (or the expected one before any).
  [[nodiscard]] Model model() const noexcept { return stream_model_.value_or(expected_.value_or(Model::kVlp16)); }
  [[nodiscard]] bool decided() const noexcept { return stream_model_.has_value(); }
  [[nodiscard]] std::optional<Model> expected() const noexcept { return expected_; }
  // Why the last rejection happened, e.g. "product id 0x28 (VLP-32C) … lidar.model vlp16".
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }
  // Microseconds between the two 0x21 packets that decided, 0 before.
  [[nodiscard]] std::uint32_t measured_period_us() const noexcept { return measured_period_us_; }

 private:
  // The model of a 0x21 packet by timing; nullopt while undecided (or rejected: reason_ set).
  std::optional<Model> early_model(std::span<const std::uint8_t> packet, bool& rejected);
  Verdict reject(std::uint8_t id, std::string reason);

  std::optional<Model> expected_;
  std::optional<Model> stream_model_;
  enum class Early : std::uint8_t { kUnknown, kVlp16, kHdl32e, kNeither };
  Early early_ = Early::kUnknown;
  bool have_previous_ = false;
  std::uint32_t previous_toh_us_ = 0;
  std::uint8_t previous_mode_ = 0;
  unsigned inconclusive_ = 0;
  std::uint32_t measured_period_us_ = 0;
  std::uint8_t rejected_id_ = 0;
  std::string reason_;
};

}  // namespace trajroi::vlp16
