#pragma once

// What the view's server needs of HTTP/1.1 (RFC 9112): a request's head parsed from the bytes
// received so far, the WebSocket upgrade recognised, and response heads. Pure.
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace trajroi::view {

struct HttpRequest {
  std::string method, target, version;
  std::vector<std::pair<std::string, std::string>> headers;  // names as sent
  // A header's value (names compared without case), or "" when absent.
  [[nodiscard]] std::string_view header(std::string_view name) const noexcept;
  // The target without its query ("/ws?x=1" → "/ws").
  [[nodiscard]] std::string_view path() const noexcept;
};

struct HttpParse {
  enum class Status : unsigned char { kIncomplete, kDone, kBad };
  Status status = Status::kIncomplete;
  HttpRequest request;
  std::size_t consumed = 0;  // the head's bytes, up to and with the empty line
  std::string error;         // kBad: why (e.g. "request head longer than 8192 bytes")
};

inline constexpr std::size_t kMaxRequestHead = 8192;

[[nodiscard]] HttpParse parse_request(std::string_view bytes);

// An upgrade to WebSocket version 13 (RFC 6455 §4.2.1): GET, Upgrade: websocket, Connection:
// upgrade, a Sec-WebSocket-Key. "" when it is one, else why not.
[[nodiscard]] std::string websocket_upgrade_problem(const HttpRequest& request);

// "HTTP/1.1 <status> <reason>" with Content-Type, Content-Length, Cache-Control: no-store and
// Connection: close (or keep-alive), and the blank line.
[[nodiscard]] std::string response_head(int status, std::string_view reason, std::string_view content_type,
                                        std::size_t content_length, bool keep_alive);
// The 101 Switching Protocols answer to an upgrade.
[[nodiscard]] std::string websocket_accept_head(const HttpRequest& request);

}  // namespace trajroi::view
