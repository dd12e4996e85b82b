#pragma once

// Where RTK corrections come from (gnss.corrections.url): an NTRIP caster, a TCP or UDP stream
// of RTCM3, a second serial port (a radio), or an LCM channel carrying rtcm_t. Pure.
#include <cstdint>
#include <string>
#include <string_view>

#include "trajroi/corrections/ntrip.hpp"

namespace trajroi::corrections {

struct CorrectionsUrl {
  enum class Kind : std::uint8_t { kNtrip, kTcp, kUdp, kSerial, kLcm };
  Kind kind = Kind::kNtrip;
  NtripUrl ntrip;            // kNtrip; kTcp uses its host and port
  std::string bind_address;  // kUdp: the local address to bind ("0.0.0.0": any)
  std::uint16_t port = 0;    // kUdp: the local port
  std::string device;        // kSerial
  int baud = 57600;          // kSerial (?baud=)
  std::string channel;       // kLcm: on the daemon's LCM URL
  // As the URL was given, without a password: for logs and the status.
  [[nodiscard]] std::string redacted() const;
};

// ntrip://[user[:password]@]host[:port]/mountpoint[?version=1|2]
// tcp://host:port              a server that streams RTCM3 (str2str -out tcpsvr://:port)
// udp://[address]:port         datagrams of RTCM3 sent to this port (address: the one to bind)
// serial:///dev/ttyUSB1[?baud=57600]   a radio's serial port
// lcm://CHANNEL                rtcm_t messages on the daemon's LCM URL
// Throws std::invalid_argument naming what is wrong.
[[nodiscard]] CorrectionsUrl parse_corrections_url(std::string_view url);

}  // namespace trajroi::corrections
