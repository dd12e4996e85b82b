#include "trajroi/configure/receiver_config.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string_view>

#include "trajroi/serial/byte_source.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vn100/command.hpp"

namespace trajroi::configure {

namespace {

using Clock = std::chrono::steady_clock;

const char* port_name(ublox::Port port) {
  switch (port) {
    case ublox::Port::kI2c:
      return "I2C";
    case ublox::Port::kUart1:
      return "UART1";
    case ublox::Port::kUart2:
      return "UART2";
    case ublox::Port::kUsb:
      return "USB";
    case ublox::Port::kSpi:
      return "SPI";
  }
  return "?";
}

// Opens the port (the first read does) within the timeout; when it does not, the failed step
// is in `r` and false returned.
bool ensure_open(serial::SerialPortSource& port, std::chrono::milliseconds timeout, Result& r) {
  const auto until = Clock::now() + timeout;
  serial::Chunk chunk;
  while (!port.is_open() && Clock::now() < until)
    (void)port.read(chunk, std::chrono::milliseconds(50));
  if (!port.is_open()) r.steps.push_back({"open " + port.describe(), false, "cannot open " + port.last_error()});
  return port.is_open();
}

// Reads for at most `timeout`, handing every chunk to `take` until it returns true.
template <class Take>
bool read_until(serial::SerialPortSource& port, std::chrono::milliseconds timeout, Take&& take) {
  const auto until = Clock::now() + timeout;
  serial::Chunk chunk;
  while (Clock::now() < until) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
    const serial::ReadStatus r = port.read(chunk, std::max(left, std::chrono::milliseconds(1)));
    if (r == serial::ReadStatus::kData && take(chunk.bytes)) return true;
    if (r == serial::ReadStatus::kDisconnected || r == serial::ReadStatus::kEnd) return false;
  }
  return false;
}

// Sends one UBX message and waits for its ACK-ACK / ACK-NAK. Returns "ACK-ACK", "ACK-NAK" or
// why there was none.
std::string ubx_exchange(serial::SerialPortSource& port, const std::vector<std::uint8_t>& frame,
                         std::chrono::milliseconds timeout) {
  const std::uint8_t cls = frame[2], id = frame[3];
  if (!port.write(frame, timeout)) return "write failed (" + port.last_error() + ")";
  ublox::Framer framer;
  std::optional<bool> acked;
  const bool answered = read_until(port, timeout, [&](std::span<const std::uint8_t> bytes) {
    framer.feed(bytes, [&](const ublox::Message& m) {
      if (m.msg_class != ublox::kClassAck || acked) return;
      const auto ack = ublox::decode_ack(m.msg_id, m.payload);
      if (ack.ok() && ack.value.msg_class == cls && ack.value.msg_id == id) acked = ack.value.acknowledged;
    });
    return acked.has_value();
  });
  if (!answered) return "no answer within " + std::to_string(timeout.count()) + " ms";
  return *acked ? "ACK-ACK" : "ACK-NAK";
}

std::string message_names(const std::vector<ublox::PoseMessage>& messages) {
  std::string out;
  for (const ublox::PoseMessage m : messages) {
    if (!out.empty()) out += ", ";
    out += m == ublox::PoseMessage::kNavPvt        ? "NAV-PVT"
           : m == ublox::PoseMessage::kNavHpposllh ? "NAV-HPPOSLLH"
                                                   : "NAV-RELPOSNED";
  }
  return out;
}

// A checksummed "$VN…*hh" sentence at the start of `text` (after `$`), its body, or nothing.
std::optional<std::string> take_sentence(std::string& text) {
  for (;;) {
    const std::size_t start = text.find('$');
    if (start == std::string::npos) {
      text.clear();
      return std::nullopt;
    }
    const std::size_t star = text.find('*', start);
    if (star == std::string::npos || star + 3 > text.size()) {
      text.erase(0, start);
      return std::nullopt;
    }
    // The last '$' before the '*': a stray '$' in binary output does not swallow the sentence.
    const std::size_t begin = text.rfind('$', star);
    const std::string body = text.substr(begin + 1, star - begin - 1);
    const std::string hex = text.substr(star + 1, 2);
    text.erase(0, star + 3);
    char* end = nullptr;
    const unsigned long sum = std::strtoul(hex.c_str(), &end, 16);
    if (end == hex.c_str() + 2 && sum == vn100::nmea_xor(body) && body.rfind("VN", 0) == 0) return body;
  }
}

// Waits for a sentence whose body starts with `prefix` (or a $VNERR); returns it, or why not.
std::string vn_answer(serial::SerialPortSource& port, const std::string& prefix, std::chrono::milliseconds timeout,
                      bool& ok) {
  std::string text, found;
  ok = false;
  const bool answered = read_until(port, timeout, [&](std::span<const std::uint8_t> bytes) {
    text.append(bytes.begin(), bytes.end());
    while (const auto body = take_sentence(text)) {
      if (body->rfind(prefix, 0) == 0 || body->rfind("VNERR", 0) == 0) {
        found = *body;
        return true;
      }
    }
    if (text.size() > 65536) text.erase(0, text.size() - 1024);
    return false;
  });
  if (!answered) return "no answer within " + std::to_string(timeout.count()) + " ms";
  ok = found.rfind("VNERR", 0) != 0;
  return "$" + found;
}

// The register's fields after "VNxRG,75,": async port and divisor in decimal, the rest hex.
std::vector<long> register_fields(const std::string& body) {
  std::vector<long> out;
  std::size_t at = body.find(',', body.find(',') + 1);  // after "VNxRG,75"
  int index = 0;
  while (at != std::string::npos) {
    const std::size_t next = body.find(',', at + 1);
    const std::string field = body.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
    out.push_back(std::strtol(field.c_str(), nullptr, index < 2 ? 10 : 16));
    ++index;
    at = next;
  }
  return out;
}

Result finish(Result r, const std::string& device) {
  r.ok = std::all_of(r.steps.begin(), r.steps.end(), [](const Step& s) { return s.ok; }) && !r.steps.empty();
  if (r.summary.empty()) r.summary = r.ok ? device + ": configured" : device + ": configuration failed";
  return r;
}

}  // namespace

ublox::Port guess_ublox_port(const std::string& device) noexcept {
  return device.find("ttyACM") != std::string::npos ? ublox::Port::kUsb : ublox::Port::kUart1;
}

Result configure_ublox(serial::SerialPortSource& port, const UbloxSettings& s) {
  Result r;
  const std::string device = port.describe();
  if (!ensure_open(port, s.timeout, r)) return finish(std::move(r), device);
  std::vector<ublox::PoseMessage> messages{ublox::PoseMessage::kNavPvt};
  if (s.high_precision) messages.push_back(ublox::PoseMessage::kNavHpposllh);
  if (s.relposned) messages.push_back(ublox::PoseMessage::kNavRelposned);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.3g Hz", s.rate_hz);

  // F9 and later: one CFG-VALSET.
  const auto valset = ublox::pose_output_configuration(ublox::Generation::kF9, s.port, s.rate_hz, messages);
  const std::string valset_answer = ubx_exchange(port, valset.front(), s.timeout);
  const std::string what = message_names(messages) + " at " + rate;
  if (valset_answer == "ACK-ACK") {
    r.steps.push_back({"CFG-VALSET (F9): " + what + " on " + port_name(s.port), true, valset_answer});
    r.summary = device + ": u-blox F9 configured: " + what + " on " + port_name(s.port);
    if (s.rtcm3_input) {
      // A separate message: a receiver that refuses it still outputs the pose.
      const std::pair<std::uint32_t, std::uint64_t> item{ublox::rtcm3_input_key(s.port), 1};
      const std::string answer = ubx_exchange(port, ublox::encode_cfg_valset(std::span(&item, 1)), s.timeout);
      const bool ok = answer == "ACK-ACK";
      r.steps.push_back({std::string("CFG-VALSET (F9): RTCM3 input on ") + port_name(s.port), ok, answer});
      r.summary += ok ? ", RTCM3 corrections accepted"
                      : "; RTCM3 input refused (" + answer + "): the corrections written will be ignored";
    }
    return finish(std::move(r), device);
  }
  // An M8 does not know CFG-VALSET: CFG-RATE, then CFG-MSG per message on this port.
  const auto m8 = ublox::pose_output_configuration(ublox::Generation::kM8, s.port, s.rate_hz, messages);
  const std::string rate_answer = ubx_exchange(port, m8.front(), s.timeout);
  if (rate_answer != "ACK-ACK") {
    r.steps.push_back({"CFG-VALSET (F9): " + what, false, valset_answer});
    r.steps.push_back({std::string("CFG-RATE (M8): ") + rate, false, rate_answer});
    r.summary = device + ": no u-blox answered (CFG-VALSET: " + valset_answer + "; CFG-RATE: " + rate_answer +
                "): wrong device or baud rate?";
    return finish(std::move(r), device);
  }
  r.steps.push_back({std::string("CFG-RATE (M8): ") + rate, true, rate_answer});
  std::string optional_refused;
  for (std::size_t k = 0; k < messages.size(); ++k) {
    const std::string name = message_names({messages[k]});
    const std::string answer = ubx_exchange(port, m8[k + 1], s.timeout);
    const bool ok = answer == "ACK-ACK";
    if (!ok && messages[k] == ublox::PoseMessage::kNavHpposllh) {
      optional_refused = " (" + name + " refused: " + answer + "; NAV-PVT's own position is used)";
      continue;  // a receiver without high-precision output: NAV-PVT alone serves
    }
    r.steps.push_back({"CFG-MSG (M8): " + name + " every solution", ok, answer});
  }
  r.summary = device + ": u-blox M8 configured: " + what + optional_refused;
  // An M8P (the M8 that does RTK) accepts RTCM3 on every port by default; CFG-PRT would need
  // the port's whole setting (baud rate included), so it is left as the receiver has it.
  if (s.rtcm3_input) r.summary += ", RTCM3 input left as the receiver has it (an M8P accepts it by default)";
  return finish(std::move(r), device);
}

Result configure_vn100(serial::SerialPortSource& port, const Vn100Settings& s) {
  Result r;
  const std::string device = port.describe();
  if (!ensure_open(port, s.timeout, r)) return finish(std::move(r), device);
  const int divisor = std::max(1, static_cast<int>(std::lround(800.0 / s.rate_hz)));
  // Common group: TimeStartup (bit 0) and YawPitchRoll (bit 3).
  const std::string command = vn100::write_binary_output(1, s.async_port, divisor, {0x0009, 0, 0, 0, 0, 0});
  const std::string body = command.substr(1, command.find('*') - 1);
  const std::string what = body + " (TimeStartup + YawPitchRoll at " + std::to_string(800 / divisor) + " Hz)";
  bool ok = false;
  std::string answer;
  if (!port.write(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(command.data()), command.size()),
                  s.timeout)) {
    answer = "write failed (" + port.last_error() + ")";
  } else {
    answer = vn_answer(port, "VNWRG,75", s.timeout, ok);
  }
  r.steps.push_back({"write " + what, ok, answer});
  if (!ok) {
    r.summary = device + ": VN-100 binary output not written: " + answer;
    return finish(std::move(r), device);
  }
  const std::string read = vn100::ascii_command("VNRRG,75");
  (void)port.write(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(read.data()), read.size()),
                   s.timeout);
  const std::string back = vn_answer(port, "VNRRG,75", s.timeout, ok);
  const bool same = ok && register_fields(back.substr(
                              1, back.find('*') == std::string::npos ? std::string::npos : back.find('*') - 1)) ==
                              register_fields(body);
  r.steps.push_back({"read back register 75", same, ok && !same ? back + " differs from " + body : back});
  r.summary = same ? device + ": VN-100 configured: " + what
                   : device + ": VN-100 register 75 read back " + back + ", not what was written (" + body + ")";
  return finish(std::move(r), device);
}

}  // namespace trajroi::configure
