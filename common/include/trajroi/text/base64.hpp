#pragma once

// Base64 (RFC 4648 §4, with padding): the WebSocket handshake's accept key, HTTP Basic
// credentials (NTRIP casters).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace trajroi::text {

[[nodiscard]] std::string base64(std::span<const std::uint8_t> bytes);
[[nodiscard]] inline std::string base64(std::string_view text) {
  return base64(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

}  // namespace trajroi::text
