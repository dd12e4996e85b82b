#pragma once

// What else a serial port may carry when the configured binary protocol does not frame: NMEA
// text ("$GPGGA,…*hh"), VectorNav's ASCII output ("$VNYMR,…*hh", or its 16-bit CRC "*hhhh")
// and RTCM3 corrections (0xD3, a 10-bit length, CRC-24Q). Only whole, checksum-correct
// sentences and frames count, so random bytes (a wrong baud rate) count as none of them. Fed
// while the port has given no frame of its own protocol; resumable across reads; pure.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "trajroi/framing/checksums.hpp"
#include "trajroi/framing/rtcm3.hpp"

namespace trajroi::framing {

struct SnifferCounters {
  std::uint64_t nmea_sentences = 0;         // checksum-correct NMEA 0183 sentences
  std::uint64_t vn100_ascii_sentences = 0;  // checksum-correct VectorNav ASCII ("$VN…")
  std::uint64_t rtcm3_frames = 0;           // CRC-correct RTCM3 frames
};

class ProtocolSniffer {
 public:
  void feed(std::span<const std::uint8_t> bytes) {
    for (const std::uint8_t b : bytes) {
      text(b);
    }
    rtcm_.feed(bytes, [this](std::span<const std::uint8_t>) { ++counters_.rtcm3_frames; });
  }
  [[nodiscard]] const SnifferCounters& counters() const noexcept { return counters_; }

 private:
  static constexpr std::size_t kMaxLine = 128;  // NMEA allows 82; VectorNav's lines are longer

  static int hex(std::uint8_t c) noexcept {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
  }
  // A line from '$' to its line feed: "$" body "*" checksum ["\r"] "\n".
  void text(std::uint8_t b) noexcept {
    if (b == '$') {
      line_size_ = 0;
      in_line_ = true;
      return;
    }
    if (!in_line_) return;
    if (b == '\n') {
      in_line_ = false;
      judge_line();
      return;
    }
    if (line_size_ == kMaxLine || b < 0x0D || b > 0x7E) {
      in_line_ = false;  // not text
      return;
    }
    line_[line_size_++] = b;
  }

  void judge_line() noexcept {
    std::size_t n = line_size_;
    if (n > 0 && line_[n - 1] == '\r') --n;
    std::size_t star = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (line_[i] == '*') {
        star = i;
        break;
      }
    }
    if (star < 5 || (n - star != 3 && n - star != 5)) return;
    std::uint32_t written = 0;
    for (std::size_t i = star + 1; i < n; ++i) {
      const int h = hex(line_[i]);
      if (h < 0) return;
      written = written * 16 + static_cast<std::uint32_t>(h);
    }
    const std::span<const std::uint8_t> body(line_.data(), star);
    const bool vectornav = line_[0] == 'V' && line_[1] == 'N';
    if (n - star == 5) {  // VectorNav's 16-bit CRC
      if (vectornav && crc16_ccitt(body) == written) ++counters_.vn100_ascii_sentences;
      return;
    }
    std::uint8_t x = 0;
    for (const std::uint8_t c : body)
      x ^= c;
    if (x != written) return;
    if (vectornav) {
      ++counters_.vn100_ascii_sentences;
    } else {
      ++counters_.nmea_sentences;
    }
  }

  std::array<std::uint8_t, kMaxLine> line_{};
  std::size_t line_size_ = 0;
  bool in_line_ = false;
  // RTCM3 frames: a start that fails (a 0xD3 inside other bytes) is dropped one byte on, so a
  // real frame that began inside a false one is still found.
  Rtcm3Framer rtcm_;
  SnifferCounters counters_;
};

}  // namespace trajroi::framing
