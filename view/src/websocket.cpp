#include "trajroi/view/websocket.hpp"

#include <bit>

#include "trajroi/text/base64.hpp"

namespace trajroi::view {
namespace {

constexpr std::string_view kWebSocketGuid = "258EAFA5-E914-47DA-95CA-C5AB0DC85B11";  // RFC 6455 §1.3

std::uint32_t load_be32(const std::uint8_t* p) noexcept {
  return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | p[3];
}

}  // namespace

std::array<std::uint8_t, 20> sha1(std::span<const std::uint8_t> bytes) {
  std::uint32_t h[5] = {0x67452301, 0xEFCDAB89, 0x98BADCFE, 0x10325476, 0xC3D2E1F0};
  // The message, a 1 bit, zeros to 56 mod 64, the length in bits (big-endian 64).
  std::vector<std::uint8_t> m(bytes.begin(), bytes.end());
  const std::uint64_t bits = static_cast<std::uint64_t>(bytes.size()) * 8;
  m.push_back(0x80);
  while (m.size() % 64 != 56)
    m.push_back(0);
  for (int i = 7; i >= 0; --i)
    m.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
  for (std::size_t block = 0; block < m.size(); block += 64) {
    std::uint32_t w[80];
    for (int t = 0; t < 16; ++t)
      w[t] = load_be32(&m[block + 4 * static_cast<std::size_t>(t)]);
    for (int t = 16; t < 80; ++t)
      w[t] = std::rotl(w[t - 3] ^ w[t - 8] ^ w[t - 14] ^ w[t - 16], 1);
    std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4];
    for (int t = 0; t < 80; ++t) {
      std::uint32_t f = 0, k = 0;
      if (t < 20) {
        f = (b & c) | (~b & d);
        k = 0x5A827999;
      } else if (t < 40) {
        f = b ^ c ^ d;
        k = 0x6ED9EBA1;
      } else if (t < 60) {
        f = (b & c) | (b & d) | (c & d);
        k = 0x8F1BBCDC;
      } else {
        f = b ^ c ^ d;
        k = 0xCA62C1D6;
      }
      const std::uint32_t temp = std::rotl(a, 5) + f + e + k + w[t];
      e = d;
      d = c;
      c = std::rotl(b, 30);
      b = a;
      a = temp;
    }
    h[0] += a;
    h[1] += b;
    h[2] += c;
    h[3] += d;
    h[4] += e;
  }
  std::array<std::uint8_t, 20> out{};
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 4; ++j)
      out[4 * i + j] = static_cast<std::uint8_t>(h[i] >> (24 - 8 * j));
  return out;
}

std::string websocket_accept(std::string_view key) {
  std::string text(key);
  text += kWebSocketGuid;
  const auto digest = sha1(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  return text::base64(digest);
}

std::size_t server_frame_header(Opcode opcode, std::uint64_t length, std::array<std::uint8_t, 10>& out) noexcept {
  out[0] = static_cast<std::uint8_t>(0x80 | static_cast<std::uint8_t>(opcode));  // FIN
  if (length < 126) {
    out[1] = static_cast<std::uint8_t>(length);
    return 2;
  }
  if (length <= 0xFFFF) {
    out[1] = 126;
    out[2] = static_cast<std::uint8_t>(length >> 8);
    out[3] = static_cast<std::uint8_t>(length);
    return 4;
  }
  out[1] = 127;
  for (std::size_t i = 0; i < 8; ++i)
    out[2 + i] = static_cast<std::uint8_t>(length >> (56 - 8 * i));
  return 10;
}

std::vector<std::uint8_t> server_frame(Opcode opcode, std::span<const std::uint8_t> payload) {
  std::array<std::uint8_t, 10> header{};
  const std::size_t n = server_frame_header(opcode, payload.size(), header);
  std::vector<std::uint8_t> out(header.begin(), header.begin() + static_cast<std::ptrdiff_t>(n));
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

ClientFrame parse_client_frame(std::span<const std::uint8_t> bytes, std::size_t max_payload) {
  ClientFrame f;
  const auto fail = [&f](std::string why) {
    f.status = ClientFrame::Status::kError;
    f.error = std::move(why);
    return std::move(f);
  };
  if (bytes.size() < 2) return f;
  f.fin = (bytes[0] & 0x80) != 0;
  if ((bytes[0] & 0x70) != 0) return fail("reserved bits set (no extension was agreed)");
  const std::uint8_t op = bytes[0] & 0x0F;
  const bool control = (op & 0x08) != 0;
  if (op != 0x0 && op != 0x1 && op != 0x2 && op != 0x8 && op != 0x9 && op != 0xA)
    return fail("reserved opcode 0x" + std::string(1, "0123456789ABCDEF"[op]));
  f.opcode = static_cast<Opcode>(op);
  if ((bytes[1] & 0x80) == 0) return fail("unmasked client frame");
  std::uint64_t length = bytes[1] & 0x7F;
  std::size_t at = 2;
  if (length == 126) {
    if (bytes.size() < 4) return f;
    length = std::uint64_t{bytes[2]} << 8 | bytes[3];
    at = 4;
  } else if (length == 127) {
    if (bytes.size() < 10) return f;
    length = 0;
    for (std::size_t i = 0; i < 8; ++i)
      length = length << 8 | bytes[2 + i];
    at = 10;
  }
  if (control && (length > 125 || !f.fin)) return fail("control frame longer than 125 bytes or fragmented");
  if (length > max_payload)
    return fail("frame of " + std::to_string(length) + " bytes (at most " + std::to_string(max_payload) + ")");
  if (bytes.size() < at + 4 + length) return f;
  const std::uint8_t* mask = &bytes[at];
  at += 4;
  f.payload.resize(static_cast<std::size_t>(length));
  for (std::size_t i = 0; i < f.payload.size(); ++i)
    f.payload[i] = bytes[at + i] ^ mask[i % 4];
  f.consumed = at + static_cast<std::size_t>(length);
  f.status = ClientFrame::Status::kFrame;
  return f;
}

}  // namespace trajroi::view
