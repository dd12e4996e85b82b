#include "trajroi/corrections/udp_corrections.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace trajroi::corrections {

UdpCorrections::UdpCorrections(const std::string& bind_address, std::uint16_t port, double stall_s, FrameSink on_frame,
                               EventSink on_event)
    : name_("udp://" + bind_address + ":" + std::to_string(port)),
      stall_s_(stall_s),
      on_frame_(std::move(on_frame)),
      on_event_(std::move(on_event)),
      state_("waiting for datagrams on " + name_) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  if (inet_pton(AF_INET, bind_address.c_str(), &a.sin_addr) != 1)
    throw std::runtime_error(name_ + ": '" + bind_address + "' is not an IPv4 address");
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(name_ + ": cannot open a socket: " + std::strerror(errno));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error(name_ + ": cannot bind: " + std::strerror(error));
  }
}

UdpCorrections::~UdpCorrections() {
  if (fd_ >= 0) ::close(fd_);
}

short UdpCorrections::events() const noexcept {
  return POLLIN;
}

int UdpCorrections::timeout_ms(std::int64_t now_ns) const noexcept {
  if (!streaming_) return 1000;
  const auto stall_at = last_datagram_ns_ + static_cast<std::int64_t>(stall_s_ * 1e9);
  return static_cast<int>(std::max<std::int64_t>(0, (stall_at - now_ns + 999'999) / 1'000'000));
}

void UdpCorrections::service(short revents, std::int64_t now_ns) {
  if ((revents & POLLIN) != 0) {
    std::uint8_t buf[65536];
    for (;;) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n < 0) break;  // EAGAIN: all read (errors on a UDP socket are transient)
      last_datagram_ns_ = now_ns;
      if (!streaming_) {
        streaming_ = true;
        ++intake_.counters().connects;
        intake_.restart();
        state_ = "streaming from " + name_;
        if (on_event_) on_event_("receiving corrections on " + name_);
      }
      intake_.feed(std::span<const std::uint8_t>(buf, static_cast<std::size_t>(n)),
                   [this, now_ns](std::span<const std::uint8_t> frame) {
                     last_frame_ns_ = now_ns;
                     on_frame_(frame);
                   });
    }
  }
  if (streaming_ && now_ns - last_datagram_ns_ > static_cast<std::int64_t>(stall_s_ * 1e9)) {
    streaming_ = false;
    ++intake_.counters().disconnects;
    char text[48];
    std::snprintf(text, sizeof text, "no datagram for %.1f s", stall_s_);
    state_ = "waiting for datagrams on " + name_ + ": " + text;
    if (on_event_) on_event_(name_ + ": " + text);
  }
}

}  // namespace trajroi::corrections
