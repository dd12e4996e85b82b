#pragma once

// Times for raw serial logs (no host timestamps) from the sensors' own clocks, as
// ReplaySource's raw timings use them. Internal to drivers/serial.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace trajroi::serial::raw_timing {

struct TimedSpan {
  std::size_t offset = 0;
  std::size_t length = 0;
  std::int64_t time_ns = 0;
};

// A UBX log cut after each epoch's last NAV message (NAV-EOE when the log has any, else
// NAV-PVT), each piece at its epoch's iTOW after the first epoch's, from `start_ns` (iTOW's week
// rollover followed; never backwards): the receiver's own pace. Bytes that are no UBX (NMEA,
// RTCM3, noise) travel with the piece they sit in; bytes after the last epoch end go last, at
// its time. Empty when the log holds no timed NAV epoch.
[[nodiscard]] std::vector<TimedSpan> ubx_epochs(std::span<const std::uint8_t> data, std::int64_t start_ns);

// A VN-100 log of the LoggerWavesInIce logger cut after each `M,<millis>\r\n` marker, timed by
// it from `start_ns` (a marker out of order, or more than 10 s after the previous one, keeps the
// previous time). Empty when the log has no marker.
[[nodiscard]] std::vector<TimedSpan> logger_markers(std::span<const std::uint8_t> data, std::int64_t start_ns);

// Cut before each `sync` byte (a frame's start, or what looks like one), `per_second` pieces a
// second from `start_ns`.
[[nodiscard]] std::vector<TimedSpan> at_sync_bytes(std::span<const std::uint8_t> data, std::uint8_t sync,
                                                   double per_second, std::int64_t start_ns);

}  // namespace trajroi::serial::raw_timing
