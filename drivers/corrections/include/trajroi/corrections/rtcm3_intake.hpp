#pragma once

// Corrections' bytes, from any source, cut into whole CRC-correct RTCM3 frames and counted: the
// bytes, the frames by message number, the CRC failures, the bytes in no frame (not RTCM3).
// A new connection restarts the framing: a frame cut by the end of the previous one is never
// completed by the next one's bytes. Pure.
#include <cstdint>
#include <map>
#include <span>

#include "trajroi/framing/rtcm3.hpp"

namespace trajroi::corrections {

struct CorrectionCounters {
  std::uint64_t bytes = 0;        // stream bytes received (after the answer, unchunked)
  std::uint64_t frames = 0;       // whole CRC-correct RTCM3 frames handed on
  std::uint64_t crc_errors = 0;   // frame candidates whose CRC-24Q failed
  std::uint64_t other_bytes = 0;  // bytes in no frame (not RTCM3, or cut by a lost connection)
  std::uint64_t connects = 0;     // streams started
  std::uint64_t disconnects = 0;  // streams lost (closed, reset, stalled, garbage)
  std::uint64_t refusals = 0;     // answers other than a stream
  std::uint64_t gga_sent = 0;
  std::map<std::uint16_t, std::uint64_t> by_message;  // frames by RTCM message number
};

class Rtcm3Intake {
 public:
  // Calls sink(frame) for each whole frame completed by `bytes`.
  template <class Sink>
  void feed(std::span<const std::uint8_t> bytes, Sink&& sink) {
    counters_.bytes += bytes.size();
    framer_.feed(bytes, [this, &sink](std::span<const std::uint8_t> frame) {
      ++counters_.frames;
      ++counters_.by_message[framing::rtcm3_message_number(frame)];
      sink(frame);
    });
    counters_.crc_errors = seen_.checksum_errors + framer_.counters().checksum_errors;
    counters_.other_bytes = seen_.skipped_bytes + framer_.counters().skipped_bytes;
  }
  // A new stream: the bytes of a frame the previous one left unfinished are counted as other.
  void restart() noexcept;
  [[nodiscard]] CorrectionCounters& counters() noexcept { return counters_; }
  [[nodiscard]] const CorrectionCounters& counters() const noexcept { return counters_; }

 private:
  framing::Rtcm3Framer framer_;
  framing::FramerCounters seen_{};  // the framers of earlier streams
  CorrectionCounters counters_;
};

}  // namespace trajroi::corrections
