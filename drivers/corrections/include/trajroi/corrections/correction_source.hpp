#pragma once

// A source of RTK corrections driven by the caller's poll loop (never blocking it): the NTRIP
// client (also for plain TCP streams), a UDP port, a radio's serial port, an LCM channel. Each
// hands on whole CRC-correct RTCM3 frames only, counts what it received (Rtcm3Intake), and
// says every change of its state in words through the event callback.
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "trajroi/corrections/rtcm3_intake.hpp"

namespace trajroi::corrections {

class CorrectionSource {
 public:
  using FrameSink = std::function<void(std::span<const std::uint8_t> frame)>;
  using EventSink = std::function<void(const std::string& text)>;
  virtual ~CorrectionSource() = default;

  // For poll(): the descriptor (−1: none now) and what to wait for.
  [[nodiscard]] virtual int fd() const noexcept = 0;
  [[nodiscard]] virtual short events() const noexcept = 0;
  // Milliseconds until the next thing to do without the descriptor (reconnect, GGA, stall check).
  [[nodiscard]] virtual int timeout_ms(std::int64_t now_ns) const noexcept = 0;
  // After poll() (revents 0 on a timeout), with CLOCK_MONOTONIC now.
  virtual void service(short revents, std::int64_t now_ns) = 0;

  [[nodiscard]] virtual const CorrectionCounters& counters() const noexcept = 0;
  // In words: "streaming from …", "connecting to …", "waiting 4.0 s to reconnect to …: <why>".
  [[nodiscard]] virtual const std::string& state() const noexcept = 0;
  [[nodiscard]] virtual bool streaming() const noexcept = 0;
  // CLOCK_MONOTONIC of the newest frame (0: none yet).
  [[nodiscard]] virtual std::int64_t last_frame_ns() const noexcept = 0;
};

}  // namespace trajroi::corrections
