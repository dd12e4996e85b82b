#pragma once

// UBX framing (u-blox interface description, "UBX protocol"): sync 0xB5 0x62, class, id,
// payload length (uint16 LE), payload, then the 8-bit Fletcher checksum CK_A CK_B computed
// over class … payload. UBX shares the port with NMEA, RTCM3 and text; those bytes are
// skipped and counted.
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>

#include "trajroi/framing/stream_framer.hpp"

namespace trajroi::ublox {

inline constexpr std::uint8_t kSync1 = 0xB5;
inline constexpr std::uint8_t kSync2 = 0x62;
inline constexpr std::size_t kHeaderBytes = 6;  // sync ×2, class, id, length ×2
inline constexpr std::size_t kChecksumBytes = 2;
inline constexpr std::size_t kOverheadBytes = kHeaderBytes + kChecksumBytes;
// Large enough for RXM-RAWX with 128 measurements (16 + 32 × 128 bytes); longer claims are
// treated as corrupt lengths.
inline constexpr std::size_t kDefaultMaxPayloadBytes = 8192;

// Fletcher-8 over `bytes` (class … payload): {CK_A, CK_B}.
[[nodiscard]] std::uint16_t fletcher8(std::span<const std::uint8_t> bytes) noexcept;

// One UBX message: its class, id and payload (the span is valid only inside the sink).
struct Message {
  std::uint8_t msg_class = 0;
  std::uint8_t msg_id = 0;
  std::span<const std::uint8_t> payload;
  [[nodiscard]] std::uint16_t key() const noexcept { return static_cast<std::uint16_t>((msg_class << 8) | msg_id); }
};

// "NAV-PVT", "ACK-ACK", …; unknown ids are written "NAV-0x3D", unknown classes "0xF5-0x05".
[[nodiscard]] std::string message_name(std::uint8_t msg_class, std::uint8_t msg_id);

class Protocol {
 public:
  static constexpr std::uint8_t kSync = kSync1;
  explicit Protocol(std::size_t max_payload_bytes = kDefaultMaxPayloadBytes) noexcept
      : max_payload_(max_payload_bytes) {}
  [[nodiscard]] std::size_t max_frame_bytes() const noexcept { return max_payload_ + kOverheadBytes; }
  [[nodiscard]] framing::Verdict inspect(std::span<const std::uint8_t> bytes) const noexcept;
  [[nodiscard]] bool checksum_ok(std::span<const std::uint8_t> frame) const noexcept;

 private:
  std::size_t max_payload_;
};

// The UBX framer with a count of good frames per class/id.
class Framer {
 public:
  explicit Framer(std::size_t max_payload_bytes = kDefaultMaxPayloadBytes) : framer_(Protocol(max_payload_bytes)) {}

  // sink(const Message&) for each good frame, in stream order.
  template <class Sink>
  void feed(std::span<const std::uint8_t> bytes, Sink&& sink) {
    framer_.feed(bytes, [&](std::span<const std::uint8_t> frame) { deliver(frame, sink); });
  }
  template <class Sink>
  void finish(Sink&& sink) {
    framer_.finish([&](std::span<const std::uint8_t> frame) { deliver(frame, sink); });
  }

  [[nodiscard]] const framing::FramerCounters& counters() const noexcept { return framer_.counters(); }
  // Good frames by Message::key(), in key order.
  [[nodiscard]] const std::map<std::uint16_t, std::uint64_t>& frames_by_type() const noexcept { return by_type_; }

 private:
  template <class Sink>
  void deliver(std::span<const std::uint8_t> frame, Sink& sink) {
    const Message message{frame[2], frame[3], frame.subspan(kHeaderBytes, frame.size() - kOverheadBytes)};
    ++by_type_[message.key()];  // allocates only the first time a class/id is seen
    sink(message);
  }

  framing::StreamFramer<Protocol> framer_;
  std::map<std::uint16_t, std::uint64_t> by_type_;
};

}  // namespace trajroi::ublox
