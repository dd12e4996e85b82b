#include "trajroi/corrections/corrections_url.hpp"

#include <charconv>
#include <stdexcept>
#include <tuple>

namespace trajroi::corrections {
namespace {

std::invalid_argument bad(std::string_view url, const std::string& why) {
  return std::invalid_argument(std::string(url) + ": " + why);
}

// A decimal integer in [lo, hi] taking the whole text, else nullopt-like -1.
long whole_number(std::string_view s, long lo, long hi) {
  long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && end == s.data() + s.size() && v >= lo && v <= hi ? v : -1;
}

}  // namespace

std::string CorrectionsUrl::redacted() const {
  switch (kind) {
    case Kind::kNtrip:
      return ntrip.redacted();
    case Kind::kTcp:
      return "tcp://" + ntrip.host + ":" + std::to_string(ntrip.port);
    case Kind::kUdp:
      return "udp://" + bind_address + ":" + std::to_string(port);
    case Kind::kSerial:
      return "serial://" + device + "?baud=" + std::to_string(baud);
    case Kind::kLcm:
      return "lcm://" + channel;
  }
  return "?";
}

CorrectionsUrl parse_corrections_url(std::string_view url) {
  CorrectionsUrl u;
  const std::size_t scheme_end = url.find("://");
  if (scheme_end == std::string_view::npos) throw bad(url, "not a URL (ntrip://, tcp://, udp://, serial:// or lcm://)");
  const std::string_view scheme = url.substr(0, scheme_end);
  const std::string_view rest = url.substr(scheme_end + 3);
  if (scheme == "ntrip") {
    u.kind = CorrectionsUrl::Kind::kNtrip;
    u.ntrip = parse_ntrip_url(url);
    return u;
  }
  // host:port (the host may be empty for udp: any address)
  const auto host_port = [&](bool host_required) {
    const std::size_t colon = rest.rfind(':');
    if (colon == std::string_view::npos) throw bad(url, "no port (" + std::string(scheme) + "://host:PORT)");
    const std::string_view host = rest.substr(0, colon);
    if (host_required && host.empty()) throw bad(url, "no host");
    if (host.find_first_of("/@?") != std::string_view::npos) throw bad(url, "host '" + std::string(host) + "'");
    const long port = whole_number(rest.substr(colon + 1), 1, 65535);
    if (port < 0) throw bad(url, "port '" + std::string(rest.substr(colon + 1)) + "' (1 … 65535)");
    return std::pair{std::string(host), static_cast<std::uint16_t>(port)};
  };
  if (scheme == "tcp") {
    u.kind = CorrectionsUrl::Kind::kTcp;
    std::tie(u.ntrip.host, u.ntrip.port) = host_port(true);
    return u;
  }
  if (scheme == "udp") {
    u.kind = CorrectionsUrl::Kind::kUdp;
    std::tie(u.bind_address, u.port) = host_port(false);
    if (u.bind_address.empty()) u.bind_address = "0.0.0.0";
    return u;
  }
  if (scheme == "serial") {
    u.kind = CorrectionsUrl::Kind::kSerial;
    std::string_view device = rest;
    if (const std::size_t q = device.find('?'); q != std::string_view::npos) {
      const std::string_view query = device.substr(q + 1);
      device = device.substr(0, q);
      if (!query.starts_with("baud=")) throw bad(url, "unknown option '" + std::string(query) + "' (baud=N)");
      const long baud = whole_number(query.substr(5), 1, 4'000'000);
      if (baud < 0) throw bad(url, "baud rate '" + std::string(query.substr(5)) + "'");
      u.baud = static_cast<int>(baud);
    }
    if (!device.starts_with('/')) throw bad(url, "no device path (serial:///dev/ttyUSB1)");
    u.device = std::string(device);
    return u;
  }
  if (scheme == "lcm") {
    u.kind = CorrectionsUrl::Kind::kLcm;
    if (rest.empty() || rest.find_first_of("/ ?") != std::string_view::npos)
      throw bad(url, "channel '" + std::string(rest) + "' (lcm://CHANNEL)");
    u.channel = std::string(rest);
    return u;
  }
  throw bad(url, "unknown scheme '" + std::string(scheme) + "' (ntrip, tcp, udp, serial or lcm)");
}

}  // namespace trajroi::corrections
