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

namespace trajroi::framing {

struct SnifferCounters {
  std::uint64_t nmea_sentences = 0;         // checksum-correct NMEA 0183 sentences
  std::uint64_t vn100_ascii_sentences = 0;  // checksum-correct VectorNav ASCII ("$VN…")
  std::uint64_t rtcm3_frames = 0;           // CRC-correct RTCM3 frames
};

class ProtocolSniffer {
 public:
  void feed(std::span<const std::uint8_t> bytes) noexcept {
    for (const std::uint8_t b : bytes) {
      text(b);
      rtcm(b);
    }
  }
  [[nodiscard]] const SnifferCounters& counters() const noexcept { return counters_; }

 private:
  static constexpr std::size_t kMaxLine = 128;  // NMEA allows 82; VectorNav's lines are longer
  static constexpr std::size_t kMaxRtcm = 3 + 1023 + 3;

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

  // A frame from 0xD3: 6 reserved zero bits, a 10-bit length, the message, CRC-24Q. A start
  // that fails (a 0xD3 inside other bytes) is dropped and the bytes after it looked at again,
  // so a real frame that began inside a false one is still found.
  void rtcm(std::uint8_t b) noexcept {
    if (rtcm_size_ == 0 && b != 0xD3) return;
    rtcm_[rtcm_size_++] = b;
    for (;;) {
      if (rtcm_size_ >= 2 && (rtcm_[1] & 0xFC) != 0) {
        drop_start();
        continue;
      }
      if (rtcm_size_ < 3) return;
      const std::size_t length = (static_cast<std::size_t>(rtcm_[1] & 0x03) << 8) | rtcm_[2];
      if (rtcm_size_ < 3 + length + 3) return;
      const std::uint32_t written = (static_cast<std::uint32_t>(rtcm_[3 + length]) << 16) |
                                    (static_cast<std::uint32_t>(rtcm_[4 + length]) << 8) | rtcm_[5 + length];
      if (length == 0 || crc24q(std::span<const std::uint8_t>(rtcm_.data(), 3 + length)) != written) {
        drop_start();
        continue;
      }
      ++counters_.rtcm3_frames;
      const std::size_t used = 6 + length;
      for (std::size_t i = used; i < rtcm_size_; ++i)
        rtcm_[i - used] = rtcm_[i];
      rtcm_size_ -= used;
      if (rtcm_size_ == 0) return;
      if (rtcm_[0] != 0xD3) drop_start();
    }
  }
  // Drops the buffer's first byte and whatever follows up to the next 0xD3.
  void drop_start() noexcept {
    std::size_t next = 1;
    while (next < rtcm_size_ && rtcm_[next] != 0xD3)
      ++next;
    for (std::size_t i = next; i < rtcm_size_; ++i)
      rtcm_[i - next] = rtcm_[i];
    rtcm_size_ -= next;
  }

  std::array<std::uint8_t, kMaxLine> line_{};
  std::size_t line_size_ = 0;
  bool in_line_ = false;
  std::array<std::uint8_t, kMaxRtcm> rtcm_{};
  std::size_t rtcm_size_ = 0;
  SnifferCounters counters_;
};

}  // namespace trajroi::framing
