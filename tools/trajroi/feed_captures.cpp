#include "feed_captures.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "trajroi/framing/little_endian.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vlp16/packet_source.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::cli::feed {
namespace {


std::vector<std::uint8_t> read_bytes(const std::string& file) {
  std::FILE* f = std::fopen(file.c_str(), "rb");
  if (f == nullptr) throw std::runtime_error(file + ": " + std::strerror(errno));
  std::vector<std::uint8_t> bytes;
  std::uint8_t buffer[65536];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;)
    bytes.insert(bytes.end(), buffer, buffer + n);
  std::fclose(f);
  return bytes;
}

// A raw UBX log cut after each epoch's last NAV message (NAV-EOE, else NAV-PVT), each chunk
// timed by its epoch's iTOW: the receiver's own pace. Bytes that are no UBX (NMEA, noise)
// travel with the chunk they sit in.
std::vector<TimedChunk> ubx_chunks(const std::string& file) {
  const std::vector<std::uint8_t> b = read_bytes(file);
  constexpr std::uint8_t kIdNavEoe = 0x61;
  // The receiver's own framing (sync, length, checksum): the daemon's framer, a byte at a time
  // so that each message's end is known.
  const auto each_message = [&b](auto&& on_message) {
    ublox::Framer framer;
    for (std::size_t i = 0; i < b.size(); ++i)
      framer.feed(std::span<const std::uint8_t>(&b[i], 1), [&](const ublox::Message& m) { on_message(m, i + 1); });
  };
  bool has_eoe = false;
  each_message([&](const ublox::Message& m, std::size_t) {
    has_eoe = has_eoe || (m.msg_class == ublox::kClassNav && m.msg_id == kIdNavEoe);
  });
  const std::uint8_t epoch_end = has_eoe ? kIdNavEoe : ublox::kIdNavPvt;
  std::vector<TimedChunk> out;
  std::size_t chunk_start = 0;
  std::optional<std::uint32_t> first_itow;
  each_message([&](const ublox::Message& m, std::size_t end) {
    if (m.msg_class != ublox::kClassNav || m.msg_id != epoch_end || m.payload.size() < 4) return;
    const std::uint32_t itow = framing::le_u32(m.payload, 0);
    if (!first_itow) first_itow = itow;
    TimedChunk c;
    c.t_ns = (static_cast<std::int64_t>(itow) - static_cast<std::int64_t>(*first_itow)) * 1'000'000;
    if (!out.empty() && c.t_ns < out.back().t_ns) c.t_ns = out.back().t_ns;  // a week wrap: keep order
    c.stream = inputs::Stream::kGnss;
    c.bytes.assign(b.begin() + static_cast<std::ptrdiff_t>(chunk_start), b.begin() + static_cast<std::ptrdiff_t>(end));
    out.push_back(std::move(c));
    chunk_start = end;
  });
  if (out.empty()) throw std::runtime_error(file + ": no UBX NAV epoch found");
  return out;
}

// A raw VN-100 log cut after each `M,<millis>\r\n` marker of the LoggerWavesInIce logger, timed
// by it; without markers, cut after each binary frame's sync at `rate_hz`.
std::vector<TimedChunk> vn100_chunks(const std::string& file, double rate_hz) {
  const std::vector<std::uint8_t> b = read_bytes(file);
  std::vector<TimedChunk> out;
  std::size_t chunk_start = 0;
  std::optional<std::int64_t> first_ms;
  for (std::size_t i = 0; i + 4 < b.size(); ++i) {
    if (!(b[i] == 'M' && b[i + 1] == ',' && (i == 0 || b[i - 1] == '\n'))) continue;
    std::size_t k = i + 2;
    std::int64_t ms = 0;
    while (k < b.size() && k < i + 14 && b[k] >= '0' && b[k] <= '9')
      ms = ms * 10 + (b[k++] - '0');
    if (k == i + 2 || k + 1 >= b.size() || b[k] != '\r' || b[k + 1] != '\n') continue;
    if (!first_ms) first_ms = ms;
    TimedChunk c;
    c.t_ns = (ms - *first_ms) * 1'000'000;
    // A marker out of order (bytes that only looked like one) keeps the previous time.
    if (!out.empty() && (c.t_ns < out.back().t_ns || c.t_ns > out.back().t_ns + 10'000'000'000))
      c.t_ns = out.back().t_ns;
    c.stream = inputs::Stream::kImu;
    c.bytes.assign(b.begin() + static_cast<std::ptrdiff_t>(chunk_start),
                   b.begin() + static_cast<std::ptrdiff_t>(k + 2));
    out.push_back(std::move(c));
    chunk_start = k + 2;
  }
  if (out.empty()) {
    if (!(rate_hz > 0.0)) throw std::invalid_argument("--vn100-rate must be > 0");
    const auto period_ns = static_cast<std::int64_t>(1e9 / rate_hz);
    for (std::size_t i = 1; i <= b.size(); ++i) {
      if (i == b.size() || b[i] == 0xFA) {
        TimedChunk c;
        c.t_ns = static_cast<std::int64_t>(out.size()) * period_ns;
        c.stream = inputs::Stream::kImu;
        c.bytes.assign(b.begin() + static_cast<std::ptrdiff_t>(chunk_start),
                       b.begin() + static_cast<std::ptrdiff_t>(i));
        out.push_back(std::move(c));
        chunk_start = i;
      }
    }
  }
  return out;
}

// The capture's UDP payloads at their recorded spacing, from `start_ns`.
std::vector<TimedChunk> pcap_chunks(const std::string& file, std::int64_t start_ns, std::uint16_t position_port) {
  vlp16::PcapSource source(file);
  std::vector<TimedChunk> out;
  vlp16::Datagram d;
  std::optional<std::int64_t> first;
  while (source.next(d) == vlp16::PacketSource::Next::kDatagram) {
    if (!first) first = d.receive_time_ns;
    TimedChunk c;
    c.t_ns = start_ns + (d.receive_time_ns - *first);
    c.stream = d.destination_port == position_port ? inputs::Stream::kLidarPosition : inputs::Stream::kLidarData;
    c.bytes.assign(d.payload.begin(), d.payload.end());
    out.push_back(std::move(c));
  }
  if (!source.error().empty()) throw std::runtime_error(file + ": " + source.error());
  return out;
}

}  // namespace

std::vector<TimedChunk> capture_chunks(const CaptureFiles& o) {
  std::vector<TimedChunk> all;
  const auto append = [&all](std::vector<TimedChunk> more) {
    for (TimedChunk& c : more)
      all.push_back(std::move(c));
  };
  if (!o.ubx.empty()) append(ubx_chunks(o.ubx));
  if (!o.vn100.empty()) append(vn100_chunks(o.vn100, o.vn100_rate_hz));
  if (!o.pcap.empty()) {
    append(pcap_chunks(o.pcap, static_cast<std::int64_t>(o.lidar_after_s * 1e9), vlp16::kPositionPort));
  }
  const auto rank = [](inputs::Stream s) { return s == inputs::Stream::kGnss ? 0 : s == inputs::Stream::kImu ? 1 : 2; };
  std::stable_sort(all.begin(), all.end(), [&](const TimedChunk& a, const TimedChunk& b) {
    return a.t_ns != b.t_ns ? a.t_ns < b.t_ns : rank(a.stream) < rank(b.stream);
  });
  return all;
}

}  // namespace trajroi::cli::feed
