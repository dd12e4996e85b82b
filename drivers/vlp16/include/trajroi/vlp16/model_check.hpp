#pragma once

// Which sensor sends a packet stream. Product id 0x22 is a VLP-16. Early VLP-16 firmware
// (2014) sent 0x21, the HDL-32E's code, so a stream claiming 0x21 is accepted as a VLP-16
// only when its timing is a VLP-16's: one packet every 12 × 110.592 µs = 1327.1 µs in single
// return mode (663.6 µs in dual), where an HDL-32E sends one every 12 × 46.08 µs = 553 µs,
// and an azimuth step per firing that means 5–20 rotations per second under VLP-16 timing
// (about 0.4° at 10 Hz). Any other id is rejected at once.
#include <cstdint>
#include <span>
#include <string>

namespace trajroi::vlp16 {

class ModelCheck {
 public:
  // Undecided packets in a row (their timing unusable: repeated, reordered or far apart)
  // before the stream is rejected; a caller holding undecided packets needs this many slots.
  static constexpr unsigned kMaxUndecided = 32;

  enum class Verdict : std::uint8_t {
    kVlp16,
    kUndecided,  // a 0x21 stream whose timing has not been seen yet: hold the packet
    kRejected,
  };

  // The verdict for a packet that validate_data_packet() accepted. Once a 0x21 stream is
  // decided the verdict sticks (one sensor does not change model mid-stream).
  Verdict check(std::span<const std::uint8_t> packet) noexcept;
  // Why the last rejection happened, e.g. "product id 0x28 (VLP-32C) is not supported".
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }
  // Microseconds between the two 0x21 packets that decided, 0 before.
  [[nodiscard]] std::uint32_t measured_period_us() const noexcept { return measured_period_us_; }

 private:
  enum class Early : std::uint8_t { kUnknown, kVlp16, kHdl32e };
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
