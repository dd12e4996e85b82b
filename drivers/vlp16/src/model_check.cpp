#include "trajroi/vlp16/model_check.hpp"

#include <cmath>
#include <cstdio>

#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr double kPeriodTolerance = 0.05;  // ±5 % of one or two packet periods
constexpr double kMinRotation_hz = 4.5;    // the VLP-16 spins at 300 … 1200 rpm
constexpr double kMaxRotation_hz = 21.0;
// Two 0x21 packets further apart than this (or not after each other) say nothing about the
// period.
constexpr std::int64_t kMaxUsefulGap_us = 10'000;

std::string hex_id(std::uint8_t id) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", static_cast<unsigned>(id));
  return text;
}

}  // namespace

ModelCheck::Verdict ModelCheck::check(std::span<const std::uint8_t> packet) noexcept {
  const std::uint8_t id = product_id(packet);
  if (id == kProductVlp16) return Verdict::kVlp16;
  if (id != kProductHdl32e) {
    if (id != rejected_id_ || reason_.empty()) {  // built once per model, not per packet
      reason_ = "product id " + hex_id(id) + " (" + std::string(product_name(id)) + ") is not supported";
      rejected_id_ = id;
    }
    return Verdict::kRejected;
  }
  if (early_ == Early::kVlp16) return Verdict::kVlp16;
  if (early_ == Early::kHdl32e) return Verdict::kRejected;

  const std::uint32_t toh = timestamp_us(packet);
  const std::uint8_t mode = return_mode_byte(packet);
  const bool dual = mode == static_cast<std::uint8_t>(ReturnMode::kDual);
  const bool comparable = have_previous_ && mode == previous_mode_;
  const std::int64_t delta = comparable ? toh_delta_us(previous_toh_us_, toh) : 0;
  have_previous_ = true;
  previous_toh_us_ = toh;
  previous_mode_ = mode;
  if (delta <= 0 || delta > kMaxUsefulGap_us) {
    if (++inconclusive_ < kMaxUndecided) return Verdict::kUndecided;
    early_ = Early::kHdl32e;
    reason_ = "product id 0x21 (HDL-32E) with no usable packet timing is not supported";
    rejected_id_ = kProductHdl32e;
    return Verdict::kRejected;
  }
  measured_period_us_ = static_cast<std::uint32_t>(delta);

  const double period_us = static_cast<double>(kBlocks) * kBlockDuration_us / (dual ? 2.0 : 1.0);
  const auto near = [&](double expected) {
    return std::abs(static_cast<double>(delta) - expected) <= kPeriodTolerance * expected;
  };
  const bool vlp16_period = near(period_us) || near(2.0 * period_us);  // one packet lost at most
  // Azimuth advance over one firing, read as VLP-16 timing, as a rotation rate.
  const std::size_t next_firing = dual ? 2 : 1;
  const std::uint32_t step_cdeg =
      (static_cast<std::uint32_t>(block_azimuth(packet, next_firing)) + kAzimuthLimit - block_azimuth(packet, 0)) %
      kAzimuthLimit;
  const double rotation_hz = static_cast<double>(step_cdeg) / 36000.0 / (kBlockDuration_us * 1e-6);
  const bool vlp16_rotation = rotation_hz >= kMinRotation_hz && rotation_hz <= kMaxRotation_hz;
  if (vlp16_period && vlp16_rotation) {
    early_ = Early::kVlp16;
    return Verdict::kVlp16;
  }
  early_ = Early::kHdl32e;
  char text[200];
  std::snprintf(text, sizeof text,
                "product id 0x21 (HDL-32E) is not supported: %u µs between packets and %.2f° per firing "
                "(a VLP-16 sends one every %.0f µs, 0.4° per firing at 10 Hz)",
                measured_period_us_, step_cdeg / 100.0, period_us);
  reason_ = text;
  rejected_id_ = kProductHdl32e;
  return Verdict::kRejected;
}

}  // namespace trajroi::vlp16
