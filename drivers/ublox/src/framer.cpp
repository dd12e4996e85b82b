#include "trajroi/ublox/framer.hpp"

#include <array>
#include <cstdio>

#include "trajroi/framing/little_endian.hpp"

namespace trajroi::ublox {

std::uint16_t fletcher8(std::span<const std::uint8_t> bytes) noexcept {
  std::uint8_t a = 0;
  std::uint8_t b = 0;
  for (const std::uint8_t byte : bytes) {
    a = static_cast<std::uint8_t>(a + byte);
    b = static_cast<std::uint8_t>(b + a);
  }
  return static_cast<std::uint16_t>((a << 8) | b);
}

framing::Verdict Protocol::inspect(std::span<const std::uint8_t> bytes) const noexcept {
  using Kind = framing::Verdict::Kind;
  if (bytes.size() < 2) return {Kind::kNeedMore, 2};
  if (bytes[1] != kSync2) return {Kind::kNotSync, 0};
  if (bytes.size() < kHeaderBytes) return {Kind::kNeedMore, kHeaderBytes};
  const std::size_t payload = framing::le_u16(bytes, 4);
  if (payload > max_payload_) return {Kind::kBadLength, 0};
  return {Kind::kFrame, payload + kOverheadBytes};
}

bool Protocol::checksum_ok(std::span<const std::uint8_t> frame) const noexcept {
  const std::uint16_t expected = fletcher8(frame.subspan(2, frame.size() - 2 - kChecksumBytes));
  const std::size_t at = frame.size() - kChecksumBytes;
  return frame[at] == (expected >> 8) && frame[at + 1] == (expected & 0xFF);
}

namespace {

struct Name {
  std::uint8_t msg_class;
  std::uint8_t msg_id;
  const char* name;
};

// Names from the u-blox M8 / F9 / M10 interface descriptions; anything else is printed in hex.
constexpr std::array kNames{
    Name{0x01, 0x01, "POSECEF"}, Name{0x01, 0x02, "POSLLH"},    Name{0x01, 0x03, "STATUS"},
    Name{0x01, 0x04, "DOP"},     Name{0x01, 0x05, "ATT"},       Name{0x01, 0x06, "SOL"},
    Name{0x01, 0x07, "PVT"},     Name{0x01, 0x09, "ODO"},       Name{0x01, 0x11, "VELECEF"},
    Name{0x01, 0x12, "VELNED"},  Name{0x01, 0x13, "HPPOSECEF"}, Name{0x01, 0x14, "HPPOSLLH"},
    Name{0x01, 0x20, "TIMEGPS"}, Name{0x01, 0x21, "TIMEUTC"},   Name{0x01, 0x22, "CLOCK"},
    Name{0x01, 0x23, "TIMEGLO"}, Name{0x01, 0x24, "TIMEBDS"},   Name{0x01, 0x25, "TIMEGAL"},
    Name{0x01, 0x26, "TIMELS"},  Name{0x01, 0x27, "TIMEQZSS"},  Name{0x01, 0x30, "SVINFO"},
    Name{0x01, 0x31, "DGPS"},    Name{0x01, 0x32, "SBAS"},      Name{0x01, 0x34, "ORB"},
    Name{0x01, 0x35, "SAT"},     Name{0x01, 0x36, "COV"},       Name{0x01, 0x39, "GEOFENCE"},
    Name{0x01, 0x3B, "SVIN"},    Name{0x01, 0x3C, "RELPOSNED"}, Name{0x01, 0x42, "SLAS"},
    Name{0x01, 0x43, "SIG"},     Name{0x01, 0x60, "AOPSTATUS"}, Name{0x01, 0x61, "EOE"},
    Name{0x01, 0x62, "PL"},      Name{0x01, 0x63, "TIMENAVIC"}, Name{0x01, 0x64, "TIMETRUSTED"},
    Name{0x02, 0x13, "SFRBX"},   Name{0x02, 0x14, "MEASX"},     Name{0x02, 0x15, "RAWX"},
    Name{0x02, 0x32, "RTCM"},    Name{0x02, 0x59, "RLM"},       Name{0x02, 0x72, "COR"},
    Name{0x04, 0x00, "ERROR"},   Name{0x04, 0x01, "WARNING"},   Name{0x04, 0x02, "NOTICE"},
    Name{0x04, 0x03, "TEST"},    Name{0x04, 0x04, "DEBUG"},     Name{0x05, 0x00, "NAK"},
    Name{0x05, 0x01, "ACK"},     Name{0x06, 0x00, "PRT"},       Name{0x06, 0x01, "MSG"},
    Name{0x06, 0x02, "INF"},     Name{0x06, 0x04, "RST"},       Name{0x06, 0x08, "RATE"},
    Name{0x06, 0x09, "CFG"},     Name{0x06, 0x24, "NAV5"},      Name{0x06, 0x3E, "GNSS"},
    Name{0x06, 0x8A, "VALSET"},  Name{0x06, 0x8B, "VALGET"},    Name{0x06, 0x8C, "VALDEL"},
    Name{0x0A, 0x02, "IO"},      Name{0x0A, 0x04, "VER"},       Name{0x0A, 0x06, "MSGPP"},
    Name{0x0A, 0x07, "RXBUF"},   Name{0x0A, 0x08, "TXBUF"},     Name{0x0A, 0x09, "HW"},
    Name{0x0A, 0x0B, "HW2"},     Name{0x0A, 0x21, "RXR"},       Name{0x0A, 0x28, "GNSS"},
    Name{0x0A, 0x31, "SPAN"},    Name{0x0A, 0x36, "COMMS"},     Name{0x0A, 0x37, "HW3"},
    Name{0x0A, 0x38, "RF"},      Name{0x0D, 0x01, "TP"},        Name{0x0D, 0x03, "TM2"},
    Name{0x0D, 0x06, "VRFY"},    Name{0x10, 0x02, "MEAS"},      Name{0x10, 0x03, "RAW"},
    Name{0x10, 0x10, "STATUS"},  Name{0x10, 0x14, "ALG"},       Name{0x10, 0x15, "INS"},
    Name{0x27, 0x03, "UNIQID"},  Name{0x28, 0x00, "PVT"},       Name{0x28, 0x01, "ATT"},
    Name{0x28, 0x02, "INS"},
};

const char* class_name(std::uint8_t msg_class) noexcept {
  switch (msg_class) {
    case 0x01:
      return "NAV";
    case 0x02:
      return "RXM";
    case 0x04:
      return "INF";
    case 0x05:
      return "ACK";
    case 0x06:
      return "CFG";
    case 0x09:
      return "UPD";
    case 0x0A:
      return "MON";
    case 0x0B:
      return "AID";
    case 0x0D:
      return "TIM";
    case 0x10:
      return "ESF";
    case 0x13:
      return "MGA";
    case 0x21:
      return "LOG";
    case 0x27:
      return "SEC";
    case 0x28:
      return "HNR";
    default:
      return nullptr;
  }
}

}  // namespace

std::string message_name(std::uint8_t msg_class, std::uint8_t msg_id) {
  const char* cls = class_name(msg_class);
  char text[32];
  if (cls == nullptr) {
    std::snprintf(text, sizeof text, "0x%02X-0x%02X", msg_class, msg_id);
    return text;
  }
  for (const Name& n : kNames) {
    if (n.msg_class == msg_class && n.msg_id == msg_id) return std::string(cls) + "-" + n.name;
  }
  std::snprintf(text, sizeof text, "%s-0x%02X", cls, msg_id);
  return text;
}

}  // namespace trajroi::ublox
