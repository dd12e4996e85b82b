#include "trajroi/view/http.hpp"

#include <algorithm>
#include <cctype>

#include "trajroi/view/websocket.hpp"

namespace trajroi::view {
namespace {

bool iequals(std::string_view a, std::string_view b) noexcept {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
    s.remove_suffix(1);
  return s;
}

// A comma-separated header value holds `token` (case-insensitive).
bool has_token(std::string_view value, std::string_view token) noexcept {
  while (!value.empty()) {
    const std::size_t comma = value.find(',');
    if (iequals(trim(value.substr(0, comma)), token)) return true;
    if (comma == std::string_view::npos) break;
    value.remove_prefix(comma + 1);
  }
  return false;
}

}  // namespace

std::string_view HttpRequest::header(std::string_view name) const noexcept {
  for (const auto& [n, v] : headers)
    if (iequals(n, name)) return v;
  return {};
}

std::string_view HttpRequest::path() const noexcept {
  const std::string_view t = target;
  return t.substr(0, t.find('?'));
}

HttpParse parse_request(std::string_view bytes) {
  HttpParse r;
  const auto bad = [&r](std::string why) {
    r.status = HttpParse::Status::kBad;
    r.error = std::move(why);
    return std::move(r);
  };
  const std::size_t end = bytes.find("\r\n\r\n");
  if (end == std::string_view::npos) {
    if (bytes.size() > kMaxRequestHead)
      return bad("request head longer than " + std::to_string(kMaxRequestHead) + " bytes");
    return r;
  }
  if (end + 4 > kMaxRequestHead) return bad("request head longer than " + std::to_string(kMaxRequestHead) + " bytes");
  std::string_view head = bytes.substr(0, end + 2);
  const std::size_t line_end = head.find("\r\n");
  const std::string_view line = head.substr(0, line_end);
  const std::size_t sp1 = line.find(' ');
  const std::size_t sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos) return bad("malformed request line");
  r.request.method = std::string(line.substr(0, sp1));
  r.request.target = std::string(line.substr(sp1 + 1, sp2 - sp1 - 1));
  r.request.version = std::string(line.substr(sp2 + 1));
  if (r.request.version.rfind("HTTP/1.", 0) != 0) return bad("not HTTP/1.x: " + r.request.version);
  if (r.request.target.empty() || r.request.target.front() != '/') return bad("request target not a path");
  head.remove_prefix(line_end + 2);
  while (!head.empty()) {
    const std::size_t e = head.find("\r\n");
    const std::string_view field = head.substr(0, e);
    const std::size_t colon = field.find(':');
    if (colon == std::string_view::npos || colon == 0) return bad("malformed header line");
    r.request.headers.emplace_back(std::string(field.substr(0, colon)), std::string(trim(field.substr(colon + 1))));
    head.remove_prefix(e + 2);
  }
  r.consumed = end + 4;
  r.status = HttpParse::Status::kDone;
  return r;
}

std::string websocket_upgrade_problem(const HttpRequest& request) {
  if (request.method != "GET") return "not a GET";
  if (!has_token(request.header("Upgrade"), "websocket")) return "no Upgrade: websocket";
  if (!has_token(request.header("Connection"), "upgrade")) return "no Connection: upgrade";
  if (request.header("Sec-WebSocket-Version") != "13") return "Sec-WebSocket-Version not 13";
  if (request.header("Sec-WebSocket-Key").empty()) return "no Sec-WebSocket-Key";
  return {};
}

std::string response_head(int status, std::string_view reason, std::string_view content_type,
                          std::size_t content_length, bool keep_alive) {
  std::string h = "HTTP/1.1 " + std::to_string(status) + " " + std::string(reason) + "\r\n";
  h += "Content-Type: " + std::string(content_type) + "\r\n";
  h += "Content-Length: " + std::to_string(content_length) + "\r\n";
  h += "Cache-Control: no-store\r\n";
  h += keep_alive ? "Connection: keep-alive\r\n" : "Connection: close\r\n";
  h += "\r\n";
  return h;
}

std::string websocket_accept_head(const HttpRequest& request) {
  return "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: " +
         websocket_accept(request.header("Sec-WebSocket-Key")) + "\r\n\r\n";
}

}  // namespace trajroi::view
