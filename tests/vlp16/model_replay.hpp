#pragma once

// Replaying a capture through a StreamDecoder for the model tests: the frames, the counters and
// the model check's verdict.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16::model_test {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Collector final : FrameSink {
  std::vector<Frame> frames;
  void on_frame(const Frame& frame) override { frames.push_back(frame); }
};

struct Replayed {
  Collector frames;
  StreamCounters counters;
  Model model = Model::kVlp16;
  bool decided = false;
  std::string reason;
};

inline Replayed replay(const std::filesystem::path& path, const Calibration& calibration, StreamOptions options) {
  Replayed r;
  PcapSource source(path);
  StreamDecoder decoder(calibration, options);
  Datagram datagram;
  while (source.next(datagram) == PacketSource::Next::kDatagram) {
    if (datagram.destination_port == kPositionPort) {
      decoder.on_position_packet(datagram.payload);
    } else {
      decoder.on_data_packet(datagram.payload, datagram.receive_time_ns, r.frames);
    }
  }
  decoder.flush(r.frames);
  r.counters = decoder.counters();
  r.model = decoder.model_check().model();
  r.decided = decoder.model_check().decided();
  r.reason = decoder.model_check().reason();
  return r;
}

inline StreamOptions auto_model(double min_range_m = 0.0, double max_range_m = 1e9) {
  StreamOptions o;
  o.detect_model = true;
  o.decode.min_range_m = min_range_m;
  o.decode.max_range_m = max_range_m;
  return o;
}

// The clockwise azimuth of a point in the sensor frame (x forward, y left), degrees.
inline double azimuth_deg(double x, double y) {
  const double a = std::atan2(-y, x) / kDeg;
  return a < 0.0 ? a + 360.0 : a;
}

inline double wrapped(double d) {
  while (d > 180.0)
    d -= 360.0;
  while (d < -180.0)
    d += 360.0;
  return d;
}

}  // namespace trajroi::vlp16::model_test
