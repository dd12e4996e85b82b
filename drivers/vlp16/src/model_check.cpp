#include "trajroi/vlp16/model_check.hpp"

#include <cmath>
#include <cstdio>

#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr double kPeriodTolerance = 0.05;  // ±5 % of one or two packet periods
constexpr double kMinRotation_hz = 4.5;    // Velodyne sensors spin at 300 … 1200 rpm
constexpr double kMaxRotation_hz = 21.0;
// Two 0x21 packets further apart than this (or not after each other) say nothing about the
// period.
constexpr std::int64_t kMaxUsefulGap_us = 10'000;

std::string hex_id(std::uint8_t id) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", static_cast<unsigned>(id));
  return text;
}

std::string described(std::uint8_t id) {
  return "product id " + hex_id(id) + " (" + std::string(product_name(id)) + ")";
}

}  // namespace

ModelCheck::Verdict ModelCheck::reject(std::uint8_t id, std::string reason) {
  if (id != rejected_id_ || reason_.empty() || reason_ != reason) reason_ = std::move(reason);
  rejected_id_ = id;
  return Verdict::kRejected;
}

std::optional<Model> ModelCheck::early_model(std::span<const std::uint8_t> packet, bool& rejected) {
  rejected = false;
  if (early_ == Early::kVlp16) return Model::kVlp16;
  if (early_ == Early::kHdl32e) return Model::kHdl32e;
  if (early_ == Early::kNeither) {
    rejected = true;
    return std::nullopt;
  }
  const std::uint32_t toh = timestamp_us(packet);
  const std::uint8_t mode = return_mode_byte(packet);
  const bool dual = mode == static_cast<std::uint8_t>(ReturnMode::kDual);
  const bool comparable = have_previous_ && mode == previous_mode_;
  const std::int64_t delta = comparable ? toh_delta_us(previous_toh_us_, toh) : 0;
  have_previous_ = true;
  previous_toh_us_ = toh;
  previous_mode_ = mode;
  if (delta <= 0 || delta > kMaxUsefulGap_us) {
    if (++inconclusive_ < kMaxUndecided) return std::nullopt;
    early_ = Early::kNeither;
    rejected = true;
    reason_ = "product id 0x21 (HDL-32E) with no usable packet timing is not decoded (VLP-16 or HDL-32E?)";
    rejected_id_ = kProductHdl32e;
    return std::nullopt;
  }
  measured_period_us_ = static_cast<std::uint32_t>(delta);
  const std::size_t next_firing = dual ? 2 : 1;
  const std::uint32_t step_cdeg = azimuth_gap(block_azimuth(packet, 0), block_azimuth(packet, next_firing));
  // The model whose packet period and rotation rate (the azimuth step over one of its blocks)
  // the packets have.
  const auto fits = [&](Model m) {
    const ModelSpec& s = spec(m);
    const double period_us = s.packet_period_us(dual);
    const auto near = [&](double expected) {
      return std::abs(static_cast<double>(delta) - expected) <= kPeriodTolerance * expected;
    };
    const double rotation_hz = static_cast<double>(step_cdeg) / 36000.0 / (s.block_duration_us() * 1e-6);
    return (near(period_us) || near(2.0 * period_us)) && rotation_hz >= kMinRotation_hz &&
           rotation_hz <= kMaxRotation_hz;  // one packet lost at most
  };
  if (fits(Model::kVlp16)) {
    early_ = Early::kVlp16;
    return Model::kVlp16;
  }
  if (fits(Model::kHdl32e)) {
    early_ = Early::kHdl32e;
    return Model::kHdl32e;
  }
  early_ = Early::kNeither;
  rejected = true;
  char text[240];
  std::snprintf(text, sizeof text,
                "product id 0x21 (HDL-32E) is not decoded: %u µs between packets and %.2f° per block fit neither an "
                "HDL-32E (one every %.0f µs) nor an early VLP-16 (one every %.0f µs)",
                measured_period_us_, step_cdeg / 100.0, spec(Model::kHdl32e).packet_period_us(dual),
                spec(Model::kVlp16).packet_period_us(dual));
  reason_ = text;
  rejected_id_ = kProductHdl32e;
  return std::nullopt;
}

ModelCheck::Verdict ModelCheck::check(std::span<const std::uint8_t> packet) {
  const std::uint8_t id = product_id(packet);
  std::optional<Model> model = unambiguous_model(id);
  if (!model) {
    if (id != kProductHdl32e) return reject(id, described(id) + " is not supported");
    bool rejected = false;
    model = early_model(packet, rejected);
    if (rejected) return Verdict::kRejected;
    if (!model) return Verdict::kUndecided;
  }
  if (expected_ && *model != *expected_) {
    if (id != rejected_id_ || reason_.empty()) {
      const std::string timing =
          id == kProductHdl32e ? " (told by its timing: " + std::to_string(measured_period_us_) + " µs between packets)"
                               : "";
      reason_ = described(id) + " sends " + std::string(to_string(*model)) + " packets" + timing +
                ", but lidar.model is " + std::string(spec(*expected_).config_name) +
                ": dropped (set lidar.model: " + std::string(spec(*model).config_name) + ", or auto)";
      rejected_id_ = id;
    }
    return Verdict::kRejected;
  }
  if (!stream_model_) stream_model_ = model;
  if (*model != *stream_model_) {
    if (id != rejected_id_ || reason_.empty()) {
      reason_ = "the sensor's packets changed model mid-run, from " + std::string(to_string(*stream_model_)) + " to " +
                described(id) + ": the new model's packets are dropped";
      rejected_id_ = id;
    }
    return Verdict::kRejected;
  }
  return Verdict::kDecided;
}

}  // namespace trajroi::vlp16
