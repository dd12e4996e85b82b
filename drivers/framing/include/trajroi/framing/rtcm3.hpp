#pragma once

// RTCM 10403.x version 3 transport frames, as base stations and NTRIP casters send them: the
// preamble 0xD3, 6 reserved zero bits, a 10-bit message length (1 … 1023), the message (its
// first 12 bits are the message number: 1005 station, 1077 GPS MSM7, 1230 GLONASS biases,
// 4072 u-blox proprietary, …), and a CRC-24Q over the preamble, length and message. A frame
// passes whole or not at all: what trajroid writes into a receiver is only CRC-correct frames,
// never a piece of one. Pure.
#include <cstddef>
#include <cstdint>
#include <span>

#include "trajroi/framing/checksums.hpp"
#include "trajroi/framing/stream_framer.hpp"

namespace trajroi::framing {

inline constexpr std::size_t kRtcm3Overhead = 6;  // preamble, length (2), CRC (3)
inline constexpr std::size_t kRtcm3MaxFrame = 1023 + kRtcm3Overhead;

// The StreamFramer protocol of RTCM3 frames. A zero-length frame carries no message and is
// not one (random bytes "D3 00 00" would otherwise pass with their CRC one time in 2^24).
struct Rtcm3Protocol {
  static constexpr std::uint8_t kSync = 0xD3;
  [[nodiscard]] static constexpr std::size_t max_frame_bytes() noexcept { return kRtcm3MaxFrame; }
  [[nodiscard]] static Verdict inspect(std::span<const std::uint8_t> b) noexcept {
    if (b.size() < 3) return {Verdict::Kind::kNeedMore, 3};
    if ((b[1] & 0xFC) != 0) return {Verdict::Kind::kNotSync, 0};
    const std::size_t length = (static_cast<std::size_t>(b[1] & 0x03) << 8) | b[2];
    if (length == 0) return {Verdict::Kind::kNotSync, 0};
    return {Verdict::Kind::kFrame, length + kRtcm3Overhead};
  }
  [[nodiscard]] static bool checksum_ok(std::span<const std::uint8_t> frame) noexcept {
    const std::size_t n = frame.size() - 3;
    const std::uint32_t written =
        static_cast<std::uint32_t>(frame[n]) << 16 | static_cast<std::uint32_t>(frame[n + 1]) << 8 | frame[n + 2];
    return crc24q(frame.first(n)) == written;
  }
};

using Rtcm3Framer = StreamFramer<Rtcm3Protocol>;

// A whole frame's message number (its first 12 bits), or 0 for a message shorter than 2 bytes.
[[nodiscard]] constexpr std::uint16_t rtcm3_message_number(std::span<const std::uint8_t> frame) noexcept {
  if (frame.size() < 5 + 3) return 0;
  return static_cast<std::uint16_t>(frame[3] << 4 | frame[4] >> 4);
}

}  // namespace trajroi::framing
