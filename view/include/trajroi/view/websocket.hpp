#pragma once

// The WebSocket protocol (RFC 6455) as the view's server speaks it: the opening handshake's
// accept key, the header of an unmasked server frame, and client frames (always masked)
// parsed from the bytes received so far. Pure: bytes in, values out.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace trajroi::view {

// SHA-1 (FIPS 180-4) of `bytes`: the handshake's only use of it.
[[nodiscard]] std::array<std::uint8_t, 20> sha1(std::span<const std::uint8_t> bytes);
// Sec-WebSocket-Accept for a client's Sec-WebSocket-Key: base64(SHA-1(key + the RFC's GUID)).
[[nodiscard]] std::string websocket_accept(std::string_view key);

enum class Opcode : std::uint8_t {
  kContinuation = 0x0,
  kText = 0x1,
  kBinary = 0x2,
  kClose = 0x8,
  kPing = 0x9,
  kPong = 0xA
};

// The header of a final, unmasked server frame of `length` payload bytes into `out`: 2, 4 or
// 10 bytes (its size is returned).
std::size_t server_frame_header(Opcode opcode, std::uint64_t length, std::array<std::uint8_t, 10>& out) noexcept;
// A whole server frame (header and payload): for the small ones (close, pong, text).
[[nodiscard]] std::vector<std::uint8_t> server_frame(Opcode opcode, std::span<const std::uint8_t> payload);

struct ClientFrame {
  enum class Status : std::uint8_t {
    kIncomplete,  // more bytes needed
    kFrame,       // a frame: opcode, fin, payload; `consumed` bytes used
    kError,       // a protocol error (`error` says which): close the connection
  };
  Status status = Status::kIncomplete;
  Opcode opcode = Opcode::kContinuation;
  bool fin = false;
  std::size_t consumed = 0;
  std::vector<std::uint8_t> payload;  // unmasked
  std::string error;
};

// The first client frame in `bytes`. A client frame must be masked (RFC 6455 §5.1), use no
// reserved bits and opcodes, and carry at most `max_payload` bytes (a control frame 125).
[[nodiscard]] ClientFrame parse_client_frame(std::span<const std::uint8_t> bytes, std::size_t max_payload);

}  // namespace trajroi::view
