#pragma once

// Replaying a real capture through the pcap source and a StreamDecoder for the capture tests:
// the datagrams, return modes and azimuth wraps seen, the frames, the counters, the model
// check's verdict and the position packets' RMC.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model_replay.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16::capture_test {

using model_test::Collector;

struct Replay {
  std::size_t data_datagrams = 0;
  std::size_t position_datagrams = 0;
  std::size_t wraps = 0;  // block azimuth decreasing from one block to the next
  std::map<std::uint8_t, std::size_t> modes;
  Collector frames;
  StreamCounters counters;
  std::string model_rejection;
  std::uint32_t model_period_us = 0;  // that decided a 0x21 stream
  std::optional<PositionPacket> first_rmc, last_rmc;
};

// `ahead`: every data packet that validates is also decoded by it first and handed over with
// its points (as trajroid's input threads decode ahead of the stream).
inline Replay replay(const std::filesystem::path& path, const Calibration& calibration = Calibration::vlp16_default(),
                     StreamOptions options = {}, const PacketDecoder* ahead = nullptr) {
  Replay r;
  auto decoded_ahead = std::make_unique<DecodedPacket>();  // 11 kB: not on the stack
  DecodedPacket& decoded = *decoded_ahead;
  std::vector<Point> ahead_points;
  PcapSource source(path);
  StreamDecoder decoder(calibration, options);
  Datagram datagram;
  PacketSource::Next next;
  std::optional<std::uint16_t> last_azimuth;
  while ((next = source.next(datagram)) == PacketSource::Next::kDatagram) {
    if (datagram.destination_port == kPositionPort) {
      ++r.position_datagrams;
      decoder.on_position_packet(datagram.payload);
      continue;
    }
    ++r.data_datagrams;
    if (validate_data_packet(datagram.payload) == PacketError::kNone) {
      ++r.modes[return_mode_byte(datagram.payload)];
      for (std::size_t block = 0; block < kBlocks; ++block) {
        const std::uint16_t azimuth = block_azimuth(datagram.payload, block);
        if (last_azimuth && azimuth < *last_azimuth) ++r.wraps;
        last_azimuth = azimuth;
      }
    }
    const bool decode_ahead = ahead != nullptr && validate_data_packet(datagram.payload) == PacketError::kNone;
    if (decode_ahead) {
      ahead_points.clear();
      const PacketDecoder::Result result = ahead->decode(datagram.payload, ahead_points);
      decoded.assign(ahead_points, result);
    }
    decoder.on_data_packet(datagram.payload, datagram.receive_time_ns, r.frames, decode_ahead ? &decoded : nullptr);
  }
  EXPECT_EQ(next, PacketSource::Next::kEnd) << source.error();
  decoder.flush(r.frames);
  r.counters = decoder.counters();
  r.model_rejection = decoder.model_check().reason();
  r.model_period_us = decoder.model_check().measured_period_us();
  r.first_rmc = decoder.first_rmc();
  r.last_rmc = decoder.last_rmc();
  return r;
}

inline std::int64_t utc_ns(int y, unsigned mo, unsigned d, int h, int mi, int s) {
  namespace c = std::chrono;
  const c::sys_days date{c::year{y} / c::month{mo} / c::day{d}};
  return (c::duration_cast<c::nanoseconds>(date.time_since_epoch()) + c::hours{h} + c::minutes{mi} + c::seconds{s})
      .count();
}

}  // namespace trajroi::vlp16::capture_test
