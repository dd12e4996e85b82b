#include "trajroi/vlp16/decoder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <memory>
#include <numbers>
#include <stdexcept>

#include "trajroi/host/memory.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kCentidegToRad = kDegToRad / 100.0;
constexpr std::size_t kChannels = kFiringsPerBlock * kLasers;

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

std::array<std::uint8_t, kMaxLasers> Calibration::rings() const {
  std::array<std::uint8_t, kMaxLasers> order{};
  for (std::size_t i = 0; i < laser_count; ++i)
    order[i] = static_cast<std::uint8_t>(i);
  std::stable_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(laser_count),
                   [&](std::uint8_t a, std::uint8_t b) { return lasers[a].vert_angle_rad < lasers[b].vert_angle_rad; });
  std::array<std::uint8_t, kMaxLasers> ring{};
  for (std::size_t rank = 0; rank < laser_count; ++rank)
    ring[order[rank]] = static_cast<std::uint8_t>(rank);
  return ring;
}

// cos and sin computed once per process: of every azimuth the sensor reports (centidegrees),
// and, per model, of the in-block rotation of every channel for every gap the series covers.
// Each entry is the value decode() would otherwise compute for that block, so decoding is
// unchanged.
struct PacketDecoder::AzimuthTable {
  std::array<CosSin, kAzimuthLimit> azimuth;
};
struct PacketDecoder::StepTables {
  std::array<std::array<double, kChannels>, kSeriesGapLimit_cdeg + 1> step_cos, step_sin;
};

const PacketDecoder::AzimuthTable& PacketDecoder::azimuth_table() {
  static const std::unique_ptr<const AzimuthTable> table = [] {
    auto t = std::make_unique_for_overwrite<AzimuthTable>();  // every entry written below
    host::populate(t.get(), sizeof(AzimuthTable));
    for (std::uint32_t a = 0; a < kAzimuthLimit; ++a) {
      const double rad = static_cast<double>(a) * kCentidegToRad;
      t->azimuth[a] = {std::cos(rad), std::sin(rad)};
    }
    return std::unique_ptr<const AzimuthTable>(std::move(t));
  }();
  return *table;
}

const PacketDecoder::StepTables& PacketDecoder::step_tables(Model model) {
  const auto build = [](Model m) {
    auto t = std::make_unique_for_overwrite<StepTables>();  // every entry written below
    host::populate(t.get(), sizeof(StepTables));
    const ModelSpec& s = spec(m);
    for (std::uint32_t gap = 0; gap <= kSeriesGapLimit_cdeg; ++gap) {
      const double gap_rad = static_cast<double>(gap) * kCentidegToRad;
      for (std::size_t channel = 0; channel < kChannels; ++channel) {
        const CosSin c = small_angle(gap_rad * s.azimuth_fraction(channel));
        t->step_cos[gap][channel] = c.c;
        t->step_sin[gap][channel] = c.s;
      }
    }
    return std::unique_ptr<const StepTables>(std::move(t));
  };
  // One table per timing, each built at its first use (thread-safe static initialisation).
  switch (model) {
    case Model::kVlp16:
    case Model::kPuckHiRes: {  // the VLP-16's timing
      static const auto t = build(Model::kVlp16);
      return *t;
    }
    case Model::kVlp32c: {
      static const auto t = build(Model::kVlp32c);
      return *t;
    }
    case Model::kHdl32e:
      break;
  }
  static const auto t = build(Model::kHdl32e);
  return *t;
}

PacketDecoder::PacketDecoder(const Calibration& calibration, DecodeOptions options, Model model)
    : model_(model), options_(options), distance_unit_m_(spec(model).distance_unit_m) {
  const ModelSpec& s = spec(model);
  if (calibration.laser_count != s.lasers) {
    throw std::invalid_argument("a calibration of " + std::to_string(calibration.laser_count) + " lasers for the " +
                                std::string(s.name) + ", which has " + std::to_string(s.lasers));
  }
  const auto rings = calibration.rings();
  for (std::size_t i = 0; i < s.lasers; ++i) {
    const LaserCalibration& cal = calibration.lasers[i];
    lasers_[i] = Laser{std::cos(cal.vert_angle_rad),
                       std::sin(cal.vert_angle_rad),
                       std::cos(cal.rot_correction_rad),
                       std::sin(cal.rot_correction_rad),
                       cal.horiz_offset_m,
                       cal.dist_correction_m,
                       cal.vert_offset_m * std::sin(cal.vert_angle_rad),
                       cal.vert_offset_m * std::cos(cal.vert_angle_rad),
                       rings[i]};
    rotation_corrected_ = rotation_corrected_ || cal.rot_correction_rad != 0.0;
  }
  for (std::size_t channel = 0; channel < kChannels; ++channel) {
    channel_laser_[channel] = static_cast<std::uint8_t>(s.laser_of(channel));
    azimuth_fraction_[channel] = s.azimuth_fraction(channel);
    const std::int64_t in_block_ns = s.channel_time_ns(channel);
    for (std::size_t pair = 0; pair < kBlocks; ++pair) {
      time_ns_[pair][channel] =
          static_cast<std::uint32_t>(static_cast<std::int64_t>(pair) * s.block_duration_ns() + in_block_ns);
    }
  }
}

// Inlined into both builds of decode (below).
__attribute__((always_inline)) inline void PacketDecoder::directions(const Tables& tables, std::uint16_t azimuth,
                                                                     std::uint32_t gap, Directions& d) const noexcept {
  if (gap <= kSeriesGapLimit_cdeg && azimuth < kAzimuthLimit) {
    const CosSin base = tables.azimuth.azimuth[azimuth];
    const auto& step_cos = tables.steps.step_cos[gap];
    const auto& step_sin = tables.steps.step_sin[gap];
    for (std::size_t channel = 0; channel < kChannels; ++channel) {
      d.cos_a[channel] = base.c * step_cos[channel] - base.s * step_sin[channel];
      d.sin_a[channel] = base.s * step_cos[channel] + base.c * step_sin[channel];
    }
  } else {
    const double base_rad = static_cast<double>(azimuth) * kCentidegToRad;
    const double gap_rad = static_cast<double>(gap) * kCentidegToRad;
    for (std::size_t channel = 0; channel < kChannels; ++channel) {
      const double a = base_rad + gap_rad * azimuth_fraction_[channel];
      d.cos_a[channel] = std::cos(a);
      d.sin_a[channel] = std::sin(a);
    }
  }
  // The azimuth each channel reports: interpolated, wrapped at 360°, in degrees; 359.99999…
  // rounds up to 360 in float and is reported as 0. Centidegrees to degrees is a division by
  // 100; where the series covers the gap (every block of a sensor that turns), a
  // multiplication by 0.01 gives the same float for every azimuth, gap and channel (checked
  // one by one: Vlp16Decoder.AzimuthTimesAHundredthIsTheDivisionInFloat) at a fraction of
  // the division's cost.
  const auto base_cdeg = static_cast<double>(azimuth);
  const auto gap_cdeg = static_cast<double>(gap);
  constexpr auto kLimit = static_cast<double>(kAzimuthLimit);
  const bool multiply = gap <= kSeriesGapLimit_cdeg && azimuth < kAzimuthLimit;
#if defined(__SSE2__)
  // The same operations two channels at a time (the compiler keeps the selections as branches).
  const __m128d base = _mm_set1_pd(base_cdeg);
  const __m128d step = _mm_set1_pd(gap_cdeg);
  const __m128d limit = _mm_set1_pd(kLimit);
  const __m128 full_turn = _mm_set1_ps(360.0f);
  const auto store = [&d, full_turn](std::size_t channel, __m128d azimuth_deg) {
    const __m128 deg = _mm_cvtpd_ps(azimuth_deg);
    _mm_storel_pi(reinterpret_cast<__m64*>(&d.azimuth_deg[channel]), _mm_and_ps(deg, _mm_cmplt_ps(deg, full_turn)));
  };
  const auto wrapped = [&](std::size_t channel) {
    const __m128d a = _mm_add_pd(base, _mm_mul_pd(step, _mm_loadu_pd(&azimuth_fraction_[channel])));
    return _mm_sub_pd(a, _mm_and_pd(_mm_cmpge_pd(a, limit), limit));
  };
  if (multiply) {
    const __m128d hundredth = _mm_set1_pd(0.01);
    for (std::size_t channel = 0; channel < kChannels; channel += 2)
      store(channel, _mm_mul_pd(wrapped(channel), hundredth));
  } else {
    const __m128d hundred = _mm_set1_pd(100.0);
    for (std::size_t channel = 0; channel < kChannels; channel += 2)
      store(channel, _mm_div_pd(wrapped(channel), hundred));
  }
#else
  for (std::size_t channel = 0; channel < kChannels; ++channel) {
    double azimuth_cdeg = base_cdeg + gap_cdeg * azimuth_fraction_[channel];
    if (azimuth_cdeg >= kLimit) azimuth_cdeg -= kLimit;
    const auto azimuth_deg = static_cast<float>(multiply ? azimuth_cdeg * 0.01 : azimuth_cdeg / 100.0);
    d.azimuth_deg[channel] = azimuth_deg < 360.0f ? azimuth_deg : 0.0f;
  }
#endif
  if (rotation_corrected_) {  // θ = azimuth − rot_correction
    for (std::size_t channel = 0; channel < kChannels; ++channel) {
      const Laser& laser = lasers_[channel_laser_[channel]];
      const double c = d.cos_a[channel] * laser.cos_rot + d.sin_a[channel] * laser.sin_rot;
      d.sin_a[channel] = d.sin_a[channel] * laser.cos_rot - d.cos_a[channel] * laser.sin_rot;
      d.cos_a[channel] = c;
    }
  }
}

namespace {

// [lo, hi] widened to hold every azimuth of a firing: the azimuth bounds of a decode() (those of
// every channel, four at a time; none is NaN).
__attribute__((always_inline)) inline void widen_azimuth_bounds(const std::array<float, kChannels>& azimuth_deg,
                                                                float& lo, float& hi) noexcept {
#if defined(__SSE2__)
  __m128 min4 = _mm_loadu_ps(&azimuth_deg[0]);
  __m128 max4 = min4;
  for (std::size_t channel = 4; channel < kChannels; channel += 4) {
    const __m128 a = _mm_loadu_ps(&azimuth_deg[channel]);
    min4 = _mm_min_ps(min4, a);
    max4 = _mm_max_ps(max4, a);
  }
  min4 = _mm_min_ps(min4, _mm_movehl_ps(min4, min4));
  max4 = _mm_max_ps(max4, _mm_movehl_ps(max4, max4));
  lo = std::min(lo, _mm_cvtss_f32(_mm_min_ss(min4, _mm_shuffle_ps(min4, min4, 1))));
  hi = std::max(hi, _mm_cvtss_f32(_mm_max_ss(max4, _mm_shuffle_ps(max4, max4, 1))));
#else
  for (const float a : azimuth_deg) {
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
#endif
}

}  // namespace

PacketDecoder::Result PacketDecoder::decode(std::span<const std::uint8_t> packet, std::vector<Point>& out) const {
  static const bool avx2 = decoder_calibration().chosen == DecoderBuild::kAvx2;
  return avx2 ? decode_avx2(packet, out) : decode_baseline(packet, out);
}

PacketDecoder::Result PacketDecoder::decode_baseline(std::span<const std::uint8_t> packet,
                                                     std::vector<Point>& out) const {
  return decode_body(packet, out);
}

// The AVX2 build: 3 % less processing time on the daemon's as-fast replay of the dual-return
// corridor (Intel Xeon, AVX-512); an AVX-512 build was as much slower, and is not made. On a
// processor without AVX2 this is never called (decoder_calibration() does not choose it).
#if defined(__x86_64__)
__attribute__((target("avx2")))
#endif
PacketDecoder::Result
PacketDecoder::decode_avx2(std::span<const std::uint8_t> packet, std::vector<Point>& out) const {
  return decode_body(packet, out);
}

__attribute__((always_inline)) inline PacketDecoder::Result PacketDecoder::decode_body(
    std::span<const std::uint8_t> packet, std::vector<Point>& out) const {
  Result result;
  const std::uint8_t mode = return_mode_byte(packet);
  const bool dual = mode == static_cast<std::uint8_t>(ReturnMode::kDual);
  const std::size_t step = dual ? 2 : 1;  // blocks per firing
  const ReturnType single_type =
      mode == static_cast<std::uint8_t>(ReturnMode::kLast) ? ReturnType::kLast : ReturnType::kStrongest;
  reserve_packet_room(out);
  const double min_range = options_.min_range_m;
  const double max_range = options_.max_range_m;
  Directions d;
  // Built at the first packet of the model (a model never heard costs nothing at start).
  const Tables tables{azimuth_table(), step_tables(model_)};
  const std::size_t points_before = out.size();
  // The firings' entries lie a few hundred bytes apart in the 576 KB azimuth table, a new
  // cache line each and seldom cached: all asked for at once, their misses overlap instead of
  // each stalling its firing (as-fast replay of the dual-return corridor on an AMD EPYC, Zen 4:
  // the decoding's profile samples 83 → 68 ms, medians of 4 runs each; the same points).
  for (std::size_t block = 0; block < kBlocks; block += step) {
    const std::uint16_t azimuth = block_azimuth(packet, block);
    if (azimuth < kAzimuthLimit) __builtin_prefetch(&tables.azimuth.azimuth[azimuth]);
  }

  for (std::size_t block = 0; block < kBlocks; block += step) {
    const std::uint16_t azimuth = block_azimuth(packet, block);
    // Azimuth advance over this block's duration (a VLP-16's 110.592 µs): towards the next firing's block, or for
    // the packet's last firing, the advance over the previous one.
    const std::uint32_t gap = block + step < kBlocks ? azimuth_gap(azimuth, block_azimuth(packet, block + step))
                                                     : azimuth_gap(block_azimuth(packet, block - step), azimuth);
    directions(tables, azimuth, gap, d);
    const auto& time_ns = time_ns_[block / step];
    widen_azimuth_bounds(d.azimuth_deg, result.azimuth_min_deg, result.azimuth_max_deg);
    result.time_offset_max_ns = std::max(result.time_offset_max_ns, time_ns[kChannels - 1]);

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

      const std::size_t laser_index = channel_laser_[channel];
      const Laser& laser = lasers_[laser_index];
      const double cos_a = d.cos_a[channel];
      const double sin_a = d.sin_a[channel];
      const auto emit = [&](std::uint16_t raw, std::size_t from_block, ReturnType type) {
        const double range = static_cast<double>(raw) * distance_unit_m_ + laser.dist_correction_m;
        if (!(range >= min_range && range <= max_range)) {
          ++result.out_of_range;
          return;
        }
        const double r_xy = range * laser.cos_vert - laser.offset_sin_vert;
        out.push_back(Point{static_cast<float>(r_xy * cos_a + laser.horiz_offset_m * sin_a),
                            static_cast<float>(-r_xy * sin_a + laser.horiz_offset_m * cos_a),
                            static_cast<float>(range * laser.sin_vert + laser.offset_cos_vert),
                            static_cast<float>(range), d.azimuth_deg[channel], time_ns[channel],
                            channel_reflectivity(packet, from_block, channel), static_cast<std::uint8_t>(laser_index),
                            laser.ring, type});
      };
      if (first_raw != 0) emit(first_raw, block, first_type);
      if (second_raw != 0) emit(second_raw, block + 1, ReturnType::kStrongest);
    }
  }
  result.points = out.size() - points_before;
  return result;
}

}  // namespace trajroi::vlp16
