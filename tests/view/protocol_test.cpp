// The view's protocol pieces against their specifications' own examples: SHA-1 (FIPS 180-4
// test vectors), base64 (RFC 4648 §10), the WebSocket handshake and a masked frame (RFC 6455
// §1.3, §5.7), HTTP request heads; and the page's frame layout.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "trajroi/text/base64.hpp"
#include "trajroi/view/frames.hpp"
#include "trajroi/view/http.hpp"
#include "trajroi/view/websocket.hpp"

namespace trajroi::view {
namespace {

std::span<const std::uint8_t> bytes(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

std::string hex(std::span<const std::uint8_t> b) {
  std::string out;
  for (const std::uint8_t v : b) {
    out += "0123456789abcdef"[v >> 4];
    out += "0123456789abcdef"[v & 15];
  }
  return out;
}

TEST(Sha1, Fips180TestVectors) {
  EXPECT_EQ(hex(sha1(bytes("abc"))), "a9993e364706816aba3e25717850c26c9cd0d89d");
  EXPECT_EQ(hex(sha1(bytes(""))), "da39a3ee5e6b4b0d3255bfef95601890afd80709");
  EXPECT_EQ(hex(sha1(bytes("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"))),
            "84983e441c3bd26ebaae4aa1f95129e5e54670f1");
  const std::string million(1'000'000, 'a');
  EXPECT_EQ(hex(sha1(bytes(million))), "34aa973cd4c4daa4f61eeb2bdbad27316534016f");
}

TEST(Base64, Rfc4648Vectors) {
  using text::base64;
  EXPECT_EQ(base64(bytes("")), "");
  EXPECT_EQ(base64(bytes("f")), "Zg==");
  EXPECT_EQ(base64(bytes("fo")), "Zm8=");
  EXPECT_EQ(base64(bytes("foo")), "Zm9v");
  EXPECT_EQ(base64(bytes("foob")), "Zm9vYg==");
  EXPECT_EQ(base64(bytes("fooba")), "Zm9vYmE=");
  EXPECT_EQ(base64(bytes("foobar")), "Zm9vYmFy");
}

TEST(WebSocket, AcceptKeyOfRfc6455) {
  EXPECT_EQ(websocket_accept("dGhlIHNhbXBsZSBub25jZQ=="), "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=");
}

TEST(WebSocket, ServerFrameHeaderLengths) {
  std::array<std::uint8_t, 10> h{};
  EXPECT_EQ(server_frame_header(Opcode::kBinary, 125, h), 2U);
  EXPECT_EQ(h[0], 0x82);
  EXPECT_EQ(h[1], 125);
  EXPECT_EQ(server_frame_header(Opcode::kBinary, 126, h), 4U);
  EXPECT_EQ(h[1], 126);
  EXPECT_EQ(h[2], 0);
  EXPECT_EQ(h[3], 126);
  EXPECT_EQ(server_frame_header(Opcode::kBinary, 65536, h), 10U);
  EXPECT_EQ(h[1], 127);
  EXPECT_EQ(hex(std::span(h).subspan(2, 8)), "0000000000010000");
  // RFC 6455 §5.7: an unmasked "Hello".
  EXPECT_EQ(hex(server_frame(Opcode::kText, bytes("Hello"))), "810548656c6c6f");
}

TEST(WebSocket, MaskedClientFrameOfRfc6455) {
  const std::vector<std::uint8_t> frame = {0x81, 0x85, 0x37, 0xfa, 0x21, 0x3d, 0x7f, 0x9f, 0x4d, 0x51, 0x58};
  for (std::size_t cut = 0; cut < frame.size(); ++cut)
    EXPECT_EQ(parse_client_frame(std::span(frame).first(cut), 4096).status, ClientFrame::Status::kIncomplete) << cut;
  const ClientFrame f = parse_client_frame(frame, 4096);
  ASSERT_EQ(f.status, ClientFrame::Status::kFrame);
  EXPECT_EQ(f.opcode, Opcode::kText);
  EXPECT_TRUE(f.fin);
  EXPECT_EQ(f.consumed, frame.size());
  EXPECT_EQ(std::string(f.payload.begin(), f.payload.end()), "Hello");
}

TEST(WebSocket, ProtocolErrorsAreNamed) {
  const std::vector<std::uint8_t> unmasked = {0x81, 0x05, 'H', 'e', 'l', 'l', 'o'};
  EXPECT_EQ(parse_client_frame(unmasked, 4096).error, "unmasked client frame");
  const std::vector<std::uint8_t> reserved = {0xC1, 0x80, 0, 0, 0, 0};
  EXPECT_EQ(parse_client_frame(reserved, 4096).status, ClientFrame::Status::kError);
  const std::vector<std::uint8_t> opcode = {0x83, 0x80, 0, 0, 0, 0};
  EXPECT_EQ(parse_client_frame(opcode, 4096).error, "reserved opcode 0x3");
  const std::vector<std::uint8_t> huge = {0x82, 0xFF, 0, 0, 0, 1, 0, 0, 0, 0};
  EXPECT_EQ(parse_client_frame(huge, 4096).error, "frame of 4294967296 bytes (at most 4096)");
  const std::vector<std::uint8_t> long_ping = {0x89, 0xFE, 0, 126};
  EXPECT_EQ(parse_client_frame(long_ping, 4096).status, ClientFrame::Status::kError);
}

TEST(Http, RequestHeadAndUpgrade) {
  const std::string head =
      "GET /ws?x=1 HTTP/1.1\r\nHost: robot:8090\r\nUpgrade: websocket\r\nConnection: keep-alive, Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\nextra";
  for (std::size_t cut = 0; cut + 5 < head.size(); ++cut)
    EXPECT_EQ(parse_request(std::string_view(head).substr(0, cut)).status, HttpParse::Status::kIncomplete) << cut;
  const HttpParse p = parse_request(head);
  ASSERT_EQ(p.status, HttpParse::Status::kDone);
  EXPECT_EQ(p.consumed, head.size() - 5);
  EXPECT_EQ(p.request.path(), "/ws");
  EXPECT_EQ(p.request.header("host"), "robot:8090");
  EXPECT_EQ(websocket_upgrade_problem(p.request), "");
  EXPECT_NE(websocket_accept_head(p.request).find("Sec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n"),
            std::string::npos);
  const HttpParse plain = parse_request("GET / HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(websocket_upgrade_problem(plain.request), "no Upgrade: websocket");
}

TEST(Http, BadRequestsAreNamed) {
  EXPECT_EQ(parse_request("GARBAGE\r\n\r\n").error, "malformed request line");
  EXPECT_EQ(parse_request("GET / SPDY/3\r\n\r\n").error, "not HTTP/1.x: SPDY/3");
  EXPECT_EQ(parse_request("GET / HTTP/1.1\r\nno colon here\r\n\r\n").error, "malformed header line");
  EXPECT_EQ(parse_request(std::string(9000, 'a')).error, "request head longer than 8192 bytes");
}

std::uint32_t u32(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

TEST(Frames, SweepLayoutIsWhatThePageReads) {
  const std::vector<float> x = {1.5f, -2.0f}, y = {3.0f, 4.0f}, z = {0.25f, -0.5f};
  const std::vector<std::uint8_t> intensity = {7, 200}, sensor = {1, 0};
  const std::vector<std::string> names = {"front", "rear"};
  const std::vector<double> cx = {10.0}, cy = {-3.0}, th = {0.5};
  SweepView s;
  s.sweep_index = 1234;
  s.pose_valid = true;
  s.have_roi = true;
  s.roi = {true, 7.0, 0.0, 0.0, cx, cy, th};
  s.x = x;
  s.y = y;
  s.z = z;
  s.intensity = intensity;
  s.sensor = sensor;
  s.sensor_names = names;
  const std::vector<std::uint8_t> f = encode_sweep(s);
  EXPECT_EQ(u32(f, 0), kFrameMagic);
  EXPECT_EQ(std::string(f.begin(), f.begin() + 4), "TRV1");
  EXPECT_EQ(u32(f, 4), 1U);
  const std::uint32_t json = u32(f, 8);
  EXPECT_EQ(json % 4, 0U);
  const std::string header(f.begin() + 12, f.begin() + 12 + json);
  EXPECT_NE(header.find("\"sweep\":1234"), std::string::npos) << header;
  EXPECT_NE(header.find("\"n\":2"), std::string::npos) << header;
  EXPECT_NE(header.find("\"centres\":[[10,-3,0.5]]"), std::string::npos) << header;
  EXPECT_NE(header.find("\"sensors\":[\"front\",\"rear\"]"), std::string::npos) << header;
  float xyz[6];
  std::memcpy(xyz, f.data() + 12 + json, sizeof xyz);
  EXPECT_EQ(xyz[0], 1.5f);
  EXPECT_EQ(xyz[1], 3.0f);
  EXPECT_EQ(xyz[2], 0.25f);
  EXPECT_EQ(xyz[3], -2.0f);
  EXPECT_EQ(f[12 + json + 24], 7);
  EXPECT_EQ(f[12 + json + 25], 200);
  EXPECT_EQ(f[12 + json + 28], 1);  // the sensors, after the intensities padded to 4 bytes
  EXPECT_EQ(f[12 + json + 29], 0);
  EXPECT_EQ(f.size(), 12 + json + 24 + 4 + 4);
}

TEST(Frames, JsonEscapesAndNulls) {
  Json j;
  j.begin_object().field("a\"b", std::string_view("x\ny")).field("nan", std::numeric_limits<double>::quiet_NaN());
  j.begin_array("list").value(std::int64_t{1}).value(true).end_array().end_object();
  EXPECT_EQ(j.text(), R"({"a\"b":"x\u000ay","nan":null,"list":[1,true]})");
}

}  // namespace
}  // namespace trajroi::view
