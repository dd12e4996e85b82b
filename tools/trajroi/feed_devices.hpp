#pragma once

// trajroi feed's stand-ins for the sensors' links: a pseudo-terminal for a serial device (with
// unplug and replug), a UDP sender bound to a loopback address (it sends nowhere else), and
// malformed datagrams for the flood.
#include <arpa/inet.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "trajroi/host/clock.hpp"

namespace trajroi::cli::feed {

namespace fs = std::filesystem;

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
inline bool on_loopback(in_addr address) {
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
inline std::vector<std::uint8_t> malformed(std::span<const std::uint8_t> real, std::uint64_t k, std::mt19937& random) {
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

}  // namespace trajroi::cli::feed
