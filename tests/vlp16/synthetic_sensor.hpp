#pragma once

// A simulated VLP-16 for the stream decoder's tests, and a way to feed it through one.
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "model_replay.hpp"
#include "packet_builder.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16::stream_test {

// A VLP-16 at 10 Hz: 0.40° per firing, a packet every 1327.104 µs (single) or 663.552 µs
// (dual), every channel returning 2 m.
struct Sensor {
  ReturnMode mode = ReturnMode::kStrongest;
  std::uint8_t product = kProductVlp16;
  double toh_us = 1'000'000.0;
  std::uint32_t azimuth_cdeg = 0;
  std::int64_t receive_ns = 1'700'000'000'000'000'000;
  double period_us = 12 * 110.592;  // single; dual halves it
  std::uint16_t step_cdeg = 40;

  std::vector<std::uint8_t> next() {
    const bool dual = mode == ReturnMode::kDual;
    const double period = dual ? period_us / 2.0 : period_us;
    auto p = make_packet(static_cast<std::uint16_t>(azimuth_cdeg), step_cdeg, mode, product,
                         static_cast<std::uint32_t>(std::llround(toh_us)) % 3'600'000'000u);
    for (std::size_t block = 0; block < kBlocks; ++block) {
      for (std::size_t channel = 0; channel < 32; ++channel)
        set_return(p, block, channel, 1000, 10);
    }
    const std::size_t firings = dual ? kBlocks / 2 : kBlocks;
    azimuth_cdeg = (azimuth_cdeg + step_cdeg * static_cast<std::uint32_t>(firings)) % 36000;
    toh_us += period;
    receive_ns += std::llround(period * 1000.0);
    return p;
  }
  [[nodiscard]] std::int64_t received() const { return receive_ns; }
};

using model_test::Collector;

// Feeds `count` packets of `sensor`, letting `edit` drop (return false) or change each.
struct Outcome {
  Collector sink;
  StreamCounters counters;
  std::string rejection;
};
inline Outcome run(Sensor sensor, std::size_t count, StreamOptions options = {},
                   const std::function<bool(std::size_t, std::vector<std::uint8_t>&)>& edit = {}) {
  Outcome r;
  StreamDecoder decoder(Calibration::vlp16_default(), options);
  for (std::size_t i = 0; i < count; ++i) {
    auto p = sensor.next();
    if (edit && !edit(i, p)) continue;
    decoder.on_data_packet(p, sensor.received(), r.sink);
  }
  decoder.flush(r.sink);
  r.counters = decoder.counters();
  r.rejection = decoder.model_check().reason();
  return r;
}

constexpr std::size_t kPacketsPerTurn = 75;  // 36000 / (12 × 40)

}  // namespace trajroi::vlp16::stream_test
