#include "trajroi/ublox/config.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "trajroi/framing/little_endian.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"

namespace trajroi::ublox {

using framing::put_le_u16;
using framing::put_le_u32;

std::vector<std::uint8_t> encode_frame(std::uint8_t msg_class, std::uint8_t msg_id,
                                       std::span<const std::uint8_t> payload) {
  if (payload.size() > 0xFFFF) throw std::invalid_argument("UBX payload longer than 65535 bytes");
  std::vector<std::uint8_t> frame;
  frame.reserve(payload.size() + kOverheadBytes);
  frame.push_back(kSync1);
  frame.push_back(kSync2);
  frame.push_back(msg_class);
  frame.push_back(msg_id);
  put_le_u16(frame, static_cast<std::uint16_t>(payload.size()));
  for (const std::uint8_t b : payload)
    frame.push_back(b);
  const std::uint16_t ck = fletcher8(std::span<const std::uint8_t>(frame).subspan(2));
  frame.push_back(static_cast<std::uint8_t>(ck >> 8));
  frame.push_back(static_cast<std::uint8_t>(ck & 0xFF));
  return frame;
}

std::uint32_t msgout_key(PoseMessage message, Port port) noexcept {
  // Each message has five consecutive keys in port order I2C, UART1, UART2, USB, SPI.
  std::uint32_t i2c = 0;
  switch (message) {
    case PoseMessage::kNavPvt:
      i2c = 0x20910006;
      break;
    case PoseMessage::kNavHpposllh:
      i2c = 0x20910033;
      break;
    case PoseMessage::kNavRelposned:
      i2c = 0x2091008D;
      break;
    case PoseMessage::kNavCov:
      i2c = 0x20910083;
      break;
    case PoseMessage::kNavStatus:
      i2c = 0x2091001A;
      break;
  }
  return i2c + static_cast<std::uint32_t>(port);
}

std::uint32_t rtcm3_input_key(Port port) noexcept {
  // One group per port, two apart (INPROT, OUTPROT): I2C 0x1071…, UART1 0x1073…, UART2
  // 0x1075…, USB 0x1077…, SPI 0x1079…; item 4 is RTCM3X.
  return 0x10710004U + (static_cast<std::uint32_t>(port) << 17);
}

std::vector<std::uint8_t> encode_cfg_valset(std::span<const std::pair<std::uint32_t, std::uint64_t>> items,
                                            std::uint8_t layers) {
  if (items.size() > 64) throw std::invalid_argument("CFG-VALSET: more than 64 keys in one message");
  std::vector<std::uint8_t> payload{0x00, layers, 0x00, 0x00};  // version 0, layers, reserved
  for (const auto& [key, value] : items) {
    const unsigned size_code = (key >> 28U) & 0x7U;
    int bytes = 0;
    switch (size_code) {
      case 1:
        bytes = 1;
        break;  // one bit, stored in a byte
      case 2:
        bytes = 1;
        break;
      case 3:
        bytes = 2;
        break;
      case 4:
        bytes = 4;
        break;
      case 5:
        bytes = 8;
        break;
      default:
        throw std::invalid_argument("CFG-VALSET: key " + std::to_string(key) + " has no valid size");
    }
    const std::uint64_t limit =
        size_code == 1 ? 1 : (bytes == 8 ? ~std::uint64_t{0} : (std::uint64_t{1} << (8 * bytes)) - 1);
    if (value > limit) {
      throw std::invalid_argument("CFG-VALSET: value " + std::to_string(value) + " does not fit key " +
                                  std::to_string(key));
    }
    put_le_u32(payload, key);
    for (int i = 0; i < bytes; ++i)
      payload.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  }
  return encode_frame(kClassCfg, 0x8A, payload);
}

std::vector<std::uint8_t> encode_cfg_msg(std::uint8_t msg_class, std::uint8_t msg_id, std::uint8_t rate) {
  const std::uint8_t payload[] = {msg_class, msg_id, rate};
  return encode_frame(kClassCfg, 0x01, payload);
}

std::vector<std::uint8_t> encode_cfg_rate(std::uint16_t meas_rate_ms, std::uint16_t nav_rate) {
  if (meas_rate_ms == 0 || nav_rate == 0) throw std::invalid_argument("CFG-RATE: rates must be positive");
  std::vector<std::uint8_t> payload;
  put_le_u16(payload, meas_rate_ms);
  put_le_u16(payload, nav_rate);
  put_le_u16(payload, 1);  // timeRef: GPS time
  return encode_frame(kClassCfg, 0x08, payload);
}

namespace {

std::uint8_t message_id(PoseMessage message) noexcept {
  switch (message) {
    case PoseMessage::kNavPvt:
      return kIdNavPvt;
    case PoseMessage::kNavHpposllh:
      return kIdNavHpposllh;
    case PoseMessage::kNavRelposned:
      return kIdNavRelposned;
    case PoseMessage::kNavCov:
      return kIdNavCov;
    case PoseMessage::kNavStatus:
      return kIdNavStatus;
  }
  return kIdNavPvt;
}

}  // namespace

std::vector<std::vector<std::uint8_t>> pose_output_configuration(Generation generation, Port port, double rate_hz,
                                                                 std::span<const PoseMessage> messages) {
  if (!(rate_hz >= 0.1 && rate_hz <= 50.0)) {
    throw std::invalid_argument("GNSS output rate " + std::to_string(rate_hz) + " Hz is outside 0.1 … 50 Hz");
  }
  const auto meas_ms = static_cast<std::uint16_t>(std::lround(1000.0 / rate_hz));
  std::vector<std::vector<std::uint8_t>> out;
  if (generation == Generation::kF9) {
    std::vector<std::pair<std::uint32_t, std::uint64_t>> items{{kKeyRateMeas, meas_ms}, {kKeyRateNav, 1}};
    for (const PoseMessage m : messages)
      items.emplace_back(msgout_key(m, port), 1);
    out.push_back(encode_cfg_valset(items));
  } else {
    out.push_back(encode_cfg_rate(meas_ms, 1));
    for (const PoseMessage m : messages)
      out.push_back(encode_cfg_msg(kClassNav, message_id(m), 1));
  }
  return out;
}

}  // namespace trajroi::ublox
