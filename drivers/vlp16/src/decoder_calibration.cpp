// Which build of the packet decoder runs on this machine (baseline or AVX2): both timed on
// synthetic packets of each return mode at start, the faster chosen (TRAJROI_DECODER forces one).
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "trajroi/vlp16/decoder.hpp"
#include "trajroi/vlp16/encoder.hpp"

namespace trajroi::vlp16 {

std::string_view to_string(DecoderBuild build) noexcept {
  return build == DecoderBuild::kAvx2 ? "avx2" : "baseline";
}

namespace {

bool cpu_has_avx2() noexcept {
#if defined(__x86_64__)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

// Packets like a turning VLP-16's, every channel returning at ranges and reflectivities spread
// by a linear congruential sequence (fixed: the same packets in every process).
std::vector<std::array<std::uint8_t, kDataPacketBytes>> calibration_packets(ReturnMode mode) {
  constexpr std::size_t kPackets = 16;  // of each mode: 11 000 points, 60 µs a run here
  std::vector<std::array<std::uint8_t, kDataPacketBytes>> packets(kPackets);
  std::uint32_t state = 12345;
  const auto next = [&state] { return state = state * 1664525u + 1013904223u; };
  const std::size_t step = mode == ReturnMode::kDual ? 2 : 1;
  std::uint32_t azimuth = 0;
  for (auto& p : packets) {
    p.fill(0);
    for (std::size_t block = 0; block < kBlocks; ++block) {
      if (block % step == 0 && block > 0) azimuth = (azimuth + 40) % kAzimuthLimit;
      std::uint8_t* b = p.data() + block * kBlockBytes;
      b[0] = 0xFF;
      b[1] = 0xEE;
      b[2] = static_cast<std::uint8_t>(azimuth & 0xFF);
      b[3] = static_cast<std::uint8_t>(azimuth >> 8);
      for (std::size_t channel = 0; channel < kFiringsPerBlock * kLasers; ++channel) {
        const std::uint32_t r = next();
        // In dual mode a third of the pairs are one return (identical), as on real scenes.
        const bool same = step == 2 && block % 2 == 1 && r % 3 == 0;
        const std::uint16_t distance = same ? read_u16(p, (block - 1) * kBlockBytes + 4 + channel * 3)
                                            : static_cast<std::uint16_t>(500 + (r >> 8) % 30000);
        b[4 + channel * 3] = static_cast<std::uint8_t>(distance & 0xFF);
        b[4 + channel * 3 + 1] = static_cast<std::uint8_t>(distance >> 8);
        b[4 + channel * 3 + 2] = static_cast<std::uint8_t>(r >> 24);
      }
    }
    azimuth = (azimuth + 40) % kAzimuthLimit;
    p[kReturnModeOffset] = static_cast<std::uint8_t>(mode);
    p[kReturnModeOffset + 1] = kProductVlp16;
  }
  return packets;
}

}  // namespace

DecoderCalibration calibrate_decoder(const char* forced) {
  DecoderCalibration result;
  result.avx2_available = cpu_has_avx2();
  if (forced != nullptr && *forced != '\0') {
    const std::string_view path(forced);
    if (path == "scalar" || path == "sse2" || path == "avx2" || path == "avx512") {
      result.forced = true;
      result.chosen =
          result.avx2_available && (path == "avx2" || path == "avx512") ? DecoderBuild::kAvx2 : DecoderBuild::kBaseline;
      return result;
    }
  }
  if (!result.avx2_available) return result;
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<std::array<std::uint8_t, kDataPacketBytes>> packets = calibration_packets(ReturnMode::kDual);
  const auto strongest = calibration_packets(ReturnMode::kStrongest);
  packets.insert(packets.end(), strongest.begin(), strongest.end());
  std::vector<Point> points;
  points.reserve(packets.size() * kPointsPerPacket);
  const auto time =
      [&](PacketDecoder::Result (PacketDecoder::*build)(std::span<const std::uint8_t>, std::vector<Point>&) const) {
        double fastest = std::numeric_limits<double>::infinity();
        for (int run = 0; run < 5; ++run) {
          points.clear();
          const auto start = std::chrono::steady_clock::now();
          for (const auto& p : packets)
            (void)(decoder.*build)(p, points);
          const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
          fastest = std::min(fastest, ns / static_cast<double>(std::max<std::size_t>(points.size(), 1)));
        }
        return fastest;
      };
  result.baseline_ns_per_point = time(&PacketDecoder::decode_baseline);
  result.avx2_ns_per_point = time(&PacketDecoder::decode_avx2);
  result.chosen =
      result.baseline_ns_per_point < 0.97 * result.avx2_ns_per_point ? DecoderBuild::kBaseline : DecoderBuild::kAvx2;
  return result;
}

const DecoderCalibration& decoder_calibration() {
  static const DecoderCalibration calibration = calibrate_decoder(std::getenv("TRAJROI_SIMD"));
  return calibration;
}

std::string describe(const DecoderCalibration& c) {
  std::string text(to_string(c.chosen));
  if (c.forced) return text + " (forced by TRAJROI_SIMD)";
  if (!c.avx2_available) return text + " (no AVX2)";
  char times[96];
  std::snprintf(times, sizeof times, " (avx2 %.2f, baseline %.2f ns per point)", c.avx2_ns_per_point,
                c.baseline_ns_per_point);
  return text + times;
}

}  // namespace trajroi::vlp16
