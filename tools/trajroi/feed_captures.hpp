#pragma once

// Real captures for trajroi feed, each paced by its own recorded time: a pcap (UDP payloads by
// their destination port), a raw UBX log (by the epochs' iTOW), a raw VN-100 log from the
// LoggerWavesInIce logger (by its `M,<millis>` markers, else frame by frame at a rate), merged
// in time order.
#include <cstdint>
#include <string>
#include <vector>

#include "trajroi/inputs/input_source.hpp"

namespace trajroi::cli::feed {

// One paced piece of a capture, in a merged list.
struct TimedChunk {
  std::int64_t t_ns = 0;  // from the start of the feed
  inputs::Stream stream = inputs::Stream::kGnss;
  std::vector<std::uint8_t> bytes;
};

struct CaptureFiles {
  std::string pcap, ubx, vn100;  // empty: not fed
  double lidar_after_s = 0.0;    // the capture's first datagram this long into the serial data
  double vn100_rate_hz = 10.0;   // a VN-100 log without markers
};

// Every capture asked for, merged in time order (ties: GNSS, IMU, LiDAR, as the run merger).
// Throws naming the file that cannot be read or holds nothing to time.
[[nodiscard]] std::vector<TimedChunk> capture_chunks(const CaptureFiles& files);

}  // namespace trajroi::cli::feed
