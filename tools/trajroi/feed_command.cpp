// trajroi feed: plays a run folder into a live trajroid as its sensors would — the VLP-16
// datagrams over UDP to 127.0.0.1, the GNSS and IMU recordings through pseudo-terminals named
// by udev-like symlinks — paced by their recorded receive times. For fault tests it can
// unplug a serial device mid-frame and plug it back, flood the UDP port with copies and
// malformed packets, and send from an address that is not the sensor's. It sends to the
// loopback interface only.
#include <arpa/inet.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.hpp"
#include "trajroi/framing/little_endian.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/pacer.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vlp16/packet_source.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::cli {
namespace {

namespace fs = std::filesystem;

// "gnss@6+2": the stream's device vanishes 6 s into the data and comes back 2 s later.
struct Hangup {
  std::string stream;
  double at_s = 0.0;
  double for_s = 0.0;
};

Hangup parse_hangup(const std::string& text) {
  Hangup h;
  const auto at = text.find('@');
  const auto plus = text.find('+', at == std::string::npos ? 0 : at);
  if (at == std::string::npos || plus == std::string::npos) {
    throw std::invalid_argument("--hangup '" + text + "': expected STREAM@AT_S+FOR_S, e.g. gnss@6+2");
  }
  h.stream = text.substr(0, at);
  try {
    h.at_s = std::stod(text.substr(at + 1, plus - at - 1));
    h.for_s = std::stod(text.substr(plus + 1));
  } catch (const std::exception&) {
    throw std::invalid_argument("--hangup '" + text + "': AT_S and FOR_S must be numbers");
  }
  if (h.stream != "gnss" && h.stream != "imu")
    throw std::invalid_argument("--hangup '" + text + "': stream is gnss or imu");
  if (!(h.at_s >= 0.0) || !(h.for_s > 0.0))
    throw std::invalid_argument("--hangup '" + text + "': AT_S >= 0, FOR_S > 0");
  return h;
}

struct FeedOptions {
  std::string run_dir;
  // Or real captures, each paced by its own recorded time: a pcap (UDP payloads by their
  // destination port), a raw UBX log (by the epochs' iTOW), a raw VN-100 log from the
  // LoggerWavesInIce logger (by its `M,<millis>` markers, else at --vn100-rate).
  std::string pcap, ubx, vn100;
  double lidar_after_s = 0.0;  // the capture's first datagram this long into the serial data
  double vn100_rate_hz = 10.0;
  double until_s = 0.0;  // > 0: stop after this much data (a long serial log)
  double rate = 1.0;
  std::uint16_t data_port = vlp16::kDataPort;
  std::uint16_t position_port = vlp16::kPositionPort;
  std::string from = "127.0.0.1";  // the sensor's (loopback) address
  std::string gnss_link, imu_link;
  double wait_for_readers_s = 30.0;
  double linger_s = 0.0;  // after the data, the devices stay this long (the reader sees no unplug)
  std::vector<std::string> hangups;
  double flood_at_s = -1.0;  // < 0: no flood
  double flood_for_s = 10.0;
  double flood_factor = 20.0;
  double malformed_fraction = 0.5;
  std::string foreign_from;  // a second sender, not the sensor
  unsigned foreign_every = 10;
};

// A pseudo-terminal standing in for a serial device: the feeder holds the master; the reader
// opens the slave through a symlink. While no reader has the slave open the master polls
// POLLHUP, which tells when the reader (re)opened it.
class PtyDevice {
 public:
  PtyDevice(std::string name, fs::path link) : name_(std::move(name)), link_(std::move(link)) { appear(); }
  ~PtyDevice() { vanish(); }
  PtyDevice(const PtyDevice&) = delete;
  PtyDevice& operator=(const PtyDevice&) = delete;

  [[nodiscard]] bool present() const noexcept { return master_ >= 0; }
  [[nodiscard]] bool reader_open() const {
    if (master_ < 0) return false;
    pollfd p{master_, 0, 0};
    return ::poll(&p, 1, 0) >= 0 && (p.revents & POLLHUP) == 0;
  }
  // Writes what the reader can take now; false when there is no reader (nothing written).
  bool write(std::span<const std::uint8_t> bytes) {
    if (!reader_open()) return false;
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
      } else if (n < 0 && errno == EAGAIN) {
        pollfd p{master_, POLLOUT, 0};
        if (::poll(&p, 1, 100) <= 0) break;  // a reader that stopped reading: drop the rest
      } else if (n < 0 && errno == EINTR) {
        continue;
      } else {
        break;
      }
    }
    return true;
  }
  void appear() {
    master_ = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (master_ < 0 || grantpt(master_) != 0 || unlockpt(master_) != 0) {
      throw std::runtime_error(name_ + ": cannot open a pseudo-terminal: " + std::strerror(errno));
    }
    const char* slave = ptsname(master_);
    if (slave == nullptr) throw std::runtime_error(name_ + ": ptsname: " + std::strerror(errno));
    // The master reports POLLHUP only once a slave has been opened and closed again: do that
    // here, so that POLLHUP means "no reader yet".
    const int probe = ::open(slave, O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (probe < 0) throw std::runtime_error(name_ + ": cannot open " + slave + ": " + std::strerror(errno));
    ::close(probe);
    std::error_code ignored;
    fs::remove(link_, ignored);
    fs::create_symlink(slave, link_);
    appeared_ns_ = host::monotonic_ns();
    reopen_reported_ = false;
    std::printf("feed: %s device %s -> %s\n", name_.c_str(), link_.c_str(), slave);
    std::fflush(stdout);
  }
  void vanish() {
    if (master_ < 0) return;
    std::error_code ignored;
    fs::remove(link_, ignored);
    ::close(master_);
    master_ = -1;
  }
  // After a reappearance: prints once how long the reader took to open the device again.
  void report_reopen(std::uint64_t generation) {
    if (reopen_reported_ || generation == 0 || !reader_open()) return;
    reopen_reported_ = true;
    std::printf("feed: %s reopened by the reader %.3f s after it reappeared\n", name_.c_str(),
                static_cast<double>(host::monotonic_ns() - appeared_ns_) * 1e-9);
    std::fflush(stdout);
  }

 private:
  std::string name_;
  fs::path link_;
  int master_ = -1;
  std::int64_t appeared_ns_ = 0;
  bool reopen_reported_ = false;
};

// 127.x.y.z, or an address on the loopback interface (a test's network namespace puts a
// sensor's 10.0.0.100 there): the datagrams go to 127.0.0.1 either way and never leave.
bool on_loopback(in_addr address) {
  if ((ntohl(address.s_addr) >> 24) == 127) return true;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return false;
  bool found = false;
  for (const ifaddrs* i = list; i != nullptr && !found; i = i->ifa_next) {
    found = i->ifa_addr != nullptr && i->ifa_addr->sa_family == AF_INET && (i->ifa_flags & IFF_LOOPBACK) != 0 &&
            reinterpret_cast<const sockaddr_in*>(i->ifa_addr)->sin_addr.s_addr == address.s_addr;
  }
  freeifaddrs(list);
  return found;
}

class UdpSender {
 public:
  explicit UdpSender(const std::string& from) {
    sockaddr_in source{};
    source.sin_family = AF_INET;
    if (inet_pton(AF_INET, from.c_str(), &source.sin_addr) != 1 || !on_loopback(source.sin_addr)) {
      throw std::invalid_argument("feed sends on loopback only: '" + from +
                                  "' is neither a 127.x.y.z address nor one on the loopback interface");
    }
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<const sockaddr*>(&source), sizeof source) != 0) {
      throw std::runtime_error("UDP sender " + from + ": " + std::strerror(errno));
    }
  }
  ~UdpSender() {
    if (fd_ >= 0) ::close(fd_);
  }
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;
  void send(std::span<const std::uint8_t> bytes, std::uint16_t port) {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    for (;;) {
      const ssize_t n = ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
      if (n >= 0 || errno != ENOBUFS) break;  // loopback: ENOBUFS only under pressure; retry
    }
    ++sent_;
  }
  [[nodiscard]] std::uint64_t sent() const noexcept { return sent_; }

 private:
  int fd_ = -1;
  std::uint64_t sent_ = 0;
};

// One malformed datagram of several kinds, made from a real data packet.
std::vector<std::uint8_t> malformed(std::span<const std::uint8_t> real, std::uint64_t k, std::mt19937& random) {
  std::vector<std::uint8_t> out(real.begin(), real.end());
  out.resize(1206);  // a data packet's size, whatever came in
  switch (k % 5) {
    case 0:
      out.resize(600);
      break;  // wrong size
    case 1:
      out.front() = 0x00;
      break;  // bad block flag
    case 2:
      out.back() = 0x28;
      break;  // VLP-32C product id
    case 3:
      out.resize(1400, 0xAB);
      break;  // oversize for a Velodyne packet
    default:
      for (auto& b : out)
        b = static_cast<std::uint8_t>(random());  // noise
      break;
  }
  return out;
}

// ---- real captures ------------------------------------------------------------------------

// One paced piece of a capture, in a merged list.
struct TimedChunk {
  std::int64_t t_ns = 0;  // from the start of the feed
  inputs::Stream stream = inputs::Stream::kGnss;
  std::vector<std::uint8_t> bytes;
};

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

// Every capture asked for, merged in time order (ties: GNSS, IMU, LiDAR, as the run merger).
std::vector<TimedChunk> capture_chunks(const FeedOptions& o) {
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

void run_feed(const FeedOptions& o) {
  if (!(o.rate > 0.0)) throw std::invalid_argument("--rate must be > 0");
  if (o.foreign_every == 0) throw std::invalid_argument("--foreign-every must be >= 1");
  const fs::path dir = o.run_dir;
  // The run's recordings in receive-time order (the daemon's own merger), or the real
  // captures merged by their own times; either paced by the pacer.
  inputs::RunStreams streams;
  streams.gnss = !o.gnss_link.empty();
  streams.imu = !o.imu_link.empty();
  std::unique_ptr<inputs::RunMerger> merger;
  std::vector<TimedChunk> chunks;
  std::size_t next_chunk = 0;
  if (o.run_dir.empty()) {
    if (o.pcap.empty() && o.ubx.empty() && o.vn100.empty()) {
      throw std::invalid_argument("feed: give a run folder, or captures (--pcap, --ubx, --vn100)");
    }
    if (!o.ubx.empty() && !streams.gnss) throw std::invalid_argument("--ubx needs --gnss-link");
    if (!o.vn100.empty() && !streams.imu) throw std::invalid_argument("--vn100 needs --imu-link");
    streams.gnss = !o.ubx.empty();
    streams.imu = !o.vn100.empty();
    chunks = capture_chunks(o);
  } else {
    merger = std::make_unique<inputs::RunMerger>(dir, streams);
    for (const std::string& missing : merger->missing())
      throw std::runtime_error(missing + ": not found");
  }
  const auto next_item = [&](inputs::InputItem& item) {
    if (merger) return merger->next(item);
    if (next_chunk == chunks.size()) return false;
    const TimedChunk& c = chunks[next_chunk++];
    item.stream = c.stream;
    item.bytes = c.bytes;
    item.receive_ns = c.t_ns;
    return true;
  };
  std::unique_ptr<PtyDevice> gnss_dev, imu_dev;
  if (streams.gnss) gnss_dev = std::make_unique<PtyDevice>("gnss", o.gnss_link);
  if (streams.imu) imu_dev = std::make_unique<PtyDevice>("imu", o.imu_link);
  std::vector<Hangup> hangups;
  for (const std::string& h : o.hangups)
    hangups.push_back(parse_hangup(h));
  UdpSender sensor(o.from);
  std::unique_ptr<UdpSender> foreign;
  if (!o.foreign_from.empty()) foreign = std::make_unique<UdpSender>(o.foreign_from);

  // The readers open their devices first (a daemon starting), then the clock starts.
  const std::int64_t give_up = host::monotonic_ns() + static_cast<std::int64_t>(o.wait_for_readers_s * 1e9);
  while ((gnss_dev && !gnss_dev->reader_open()) || (imu_dev && !imu_dev->reader_open())) {
    if (host::monotonic_ns() > give_up) {
      throw std::runtime_error("no reader opened the serial devices within --wait-for-readers");
    }
    inputs::Pacer::sleep_until(host::monotonic_ns() + 10'000'000);
  }

  std::int64_t t0 = 0;
  if (merger ? !merger->peek_time(t0) : chunks.empty()) throw std::runtime_error("feed: nothing to feed");
  if (!merger) t0 = chunks.front().t_ns;
  inputs::Pacer pacer(o.rate);
  const std::int64_t start = host::monotonic_ns();
  double data_s = 0.0;
  std::uint64_t flood_sent = 0, malformed_sent = 0, foreign_sent = 0, data_sent = 0;
  std::uint64_t serial_undelivered[2] = {0, 0};
  std::uint64_t generation[2] = {0, 0};
  std::vector<bool> hung(hangups.size(), false), back(hangups.size(), false);
  std::mt19937 random(12345);
  const double flood_extra = std::max(0.0, o.flood_factor - 1.0);
  double flood_credit = 0.0;

  inputs::InputItem item;
  while (next_item(item)) {
    data_s = static_cast<double>(item.receive_ns - t0) * 1e-9;
    if (o.until_s > 0.0 && data_s > o.until_s) break;
    inputs::Pacer::sleep_until(pacer.due_ns(item.receive_ns));

    for (std::size_t i = 0; i < hangups.size(); ++i) {  // devices coming back
      PtyDevice* dev = hangups[i].stream == "gnss" ? gnss_dev.get() : imu_dev.get();
      if (dev != nullptr && hung[i] && !back[i] && data_s >= hangups[i].at_s + hangups[i].for_s) {
        back[i] = true;
        dev->appear();
        ++generation[hangups[i].stream == "gnss" ? 0 : 1];
      }
    }
    if (gnss_dev) gnss_dev->report_reopen(generation[0]);
    if (imu_dev) imu_dev->report_reopen(generation[1]);

    if (inputs::is_lidar(item.stream)) {
      const bool data = item.stream == inputs::Stream::kLidarData;
      sensor.send(item.bytes, data ? o.data_port : o.position_port);
      if (data) {
        ++data_sent;
        if (foreign && data_sent % o.foreign_every == 0) {
          foreign->send(item.bytes, o.data_port);
          ++foreign_sent;
        }
        if (o.flood_at_s >= 0.0 && data_s >= o.flood_at_s && data_s < o.flood_at_s + o.flood_for_s) {
          flood_credit += flood_extra;
          for (; flood_credit >= 1.0; flood_credit -= 1.0) {
            if (std::uniform_real_distribution<double>(0.0, 1.0)(random) < o.malformed_fraction) {
              sensor.send(malformed(item.bytes, malformed_sent++, random), o.data_port);
            } else {
              sensor.send(item.bytes, o.data_port);  // a copy: a duplicate to the decoder
            }
            ++flood_sent;
          }
        }
      }
      continue;
    }
    const int k = item.stream == inputs::Stream::kGnss ? 0 : 1;
    PtyDevice& dev = k == 0 ? *gnss_dev : *imu_dev;
    bool wrote = false;
    for (std::size_t i = 0; i < hangups.size(); ++i) {
      if (!hung[i] && hangups[i].stream == (k == 0 ? "gnss" : "imu") && data_s >= hangups[i].at_s) {
        // Unplugged in the middle of this chunk: half of it goes out, then the device is gone.
        hung[i] = true;
        const std::size_t half = item.bytes.size() / 2;
        dev.write(item.bytes.first(half));
        dev.vanish();
        std::printf("feed: %s device vanished at %.3f s of data, %zu bytes into a %zu-byte chunk\n",
                    k == 0 ? "gnss" : "imu", data_s, half, item.bytes.size());
        std::fflush(stdout);
        wrote = true;
      }
    }
    if (!wrote && !dev.write(item.bytes)) ++serial_undelivered[k];
  }
  std::printf(
      "feed: done: %.3f s of data in %.3f s; UDP sent %llu (%llu data, %llu flood of which %llu malformed)"
      " from %s, %llu from %s; serial chunks with no reader: gnss %llu, imu %llu\n",
      data_s, static_cast<double>(host::monotonic_ns() - start) * 1e-9, static_cast<unsigned long long>(sensor.sent()),
      static_cast<unsigned long long>(data_sent), static_cast<unsigned long long>(flood_sent),
      static_cast<unsigned long long>(malformed_sent), o.from.c_str(), static_cast<unsigned long long>(foreign_sent),
      o.foreign_from.empty() ? "-" : o.foreign_from.c_str(), static_cast<unsigned long long>(serial_undelivered[0]),
      static_cast<unsigned long long>(serial_undelivered[1]));
  std::fflush(stdout);
  inputs::Pacer::sleep_until(host::monotonic_ns() + static_cast<std::int64_t>(o.linger_s * 1e9));
}

}  // namespace

void add_feed_command(CLI::App& app) {
  auto o = std::make_shared<FeedOptions>();
  CLI::App* cmd = app.add_subcommand(
      "feed", "Play a run folder into a live trajroid: UDP to 127.0.0.1, serial streams through pseudo-terminals");
  cmd->add_option("run", o->run_dir, "Run folder (lidar.pcap, gnss.trjb, imu.trjb); or real captures below")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--pcap", o->pcap, "Real capture: a pcap whose UDP payloads are sent at their recorded spacing")
      ->check(CLI::ExistingFile);
  cmd->add_option("--ubx", o->ubx,
                  "Real capture: a raw UBX log, written to --gnss-link epoch by epoch at its iTOW pace")
      ->check(CLI::ExistingFile);
  cmd->add_option("--vn100", o->vn100,
                  "Real capture: a raw VN-100 log, written to --imu-link at its logger's M,<millis> pace")
      ->check(CLI::ExistingFile);
  cmd->add_option("--lidar-after", o->lidar_after_s, "With --pcap: its first datagram this many seconds into the feed")
      ->capture_default_str();
  cmd->add_option("--until", o->until_s, "Stop after this many seconds of data (0: all of it)")->capture_default_str();
  cmd->add_option("--vn100-rate", o->vn100_rate_hz, "With --vn100 and no logger markers: frames per second")
      ->capture_default_str();
  cmd->add_option("--rate", o->rate, "Pace: 1 real time, N × real time")->capture_default_str();
  cmd->add_option("--data-port", o->data_port, "UDP port for data packets")->capture_default_str();
  cmd->add_option("--position-port", o->position_port, "UDP port for position packets")->capture_default_str();
  cmd->add_option("--from", o->from, "Loopback address the sensor sends from")->capture_default_str();
  cmd->add_option("--gnss-link", o->gnss_link,
                  "Symlink to create for the GNSS pseudo-terminal (the daemon's gnss.device)");
  cmd->add_option("--imu-link", o->imu_link, "Symlink to create for the IMU pseudo-terminal (the daemon's imu.device)");
  cmd->add_option("--wait-for-readers", o->wait_for_readers_s, "Seconds to wait for the devices to be opened")
      ->capture_default_str();
  cmd->add_option("--linger", o->linger_s, "Seconds the devices stay after the data ends")->capture_default_str();
  cmd->add_option("--hangup", o->hangups, "STREAM@AT_S+FOR_S: the device vanishes mid-chunk, back FOR_S later");
  cmd->add_option("--flood-at", o->flood_at_s, "Data time (s) a UDP flood starts");
  cmd->add_option("--flood-for", o->flood_for_s, "Flood duration, s of data")->capture_default_str();
  cmd->add_option("--flood-factor", o->flood_factor, "Flood rate as a multiple of the data packet rate")
      ->capture_default_str();
  cmd->add_option("--malformed-fraction", o->malformed_fraction, "Share of the flood that is malformed")
      ->capture_default_str();
  cmd->add_option("--foreign-from", o->foreign_from, "Also send copies from this loopback address (not the sensor)");
  cmd->add_option("--foreign-every", o->foreign_every, "One copy from --foreign-from per this many data packets")
      ->capture_default_str();
  cmd->callback([o] { run_feed(*o); });
}

}  // namespace trajroi::cli
