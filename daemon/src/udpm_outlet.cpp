#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "outlet.hpp"
#include "pipeline.hpp"
#include "udpm_route.hpp"

namespace trajroi::daemon {

namespace udpm = transport::udpm;

std::unique_ptr<Outlet> make_outlet(const std::string& url) {
  if (const std::optional<LcmGroup> group = lcm_multicast_group(url)) return std::make_unique<UdpmOutlet>(url, *group);
  return std::make_unique<LcmOutlet>(url);
}

UdpmOutlet::UdpmOutlet(const std::string& url, const LcmGroup& group)
    : url_(url), group_(group), destination_(udpm_group_address(group, group.port)) {
  in_addr parsed{};
  if (inet_pton(AF_INET, group_.address.c_str(), &parsed) != 1)
    throw std::runtime_error("LCM: '" + url_ + "': '" + group_.address + "' is not an IPv4 address");
  send_fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (send_fd_ < 0) throw std::runtime_error("LCM: '" + url_ + "': cannot open a UDP socket: " + std::strerror(errno));
  const auto ttl = static_cast<unsigned char>(group_.ttl);
  const unsigned char loop = 1;
  sockaddr_in any{};
  any.sin_family = AF_INET;
  any.sin_addr.s_addr = htonl(INADDR_ANY);
  // Bound now, so that the source port the receive filters name is this socket's for good.
  if (setsockopt(send_fd_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0 ||
      setsockopt(send_fd_, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) != 0 ||
      bind(send_fd_, reinterpret_cast<const sockaddr*>(&any), sizeof any) != 0) {
    const std::string why = std::strerror(errno);
    close(send_fd_);
    throw std::runtime_error("LCM: cannot open '" + url_ + "': " + why);
  }
  own_source_ = udpm_own_source(send_fd_, group_, 500);
  if (const std::optional<UdpmRoute> route = udpm_route(group_)) {
    if (const std::string advice = udpm_route_advice(url_, group_, *route); !advice.empty()) log::info("{}", advice);
  }
}

UdpmOutlet::~UdpmOutlet() {
  close(send_fd_);
}

void UdpmOutlet::publish(const std::string& channel, std::span<const std::uint8_t> bytes) {
  std::uint64_t suppressed = 0;
  if (!udpm::split_message(channel, bytes, seqno_, datagrams_)) {
    if (send_limit_.allow(host::monotonic_ns(), suppressed))
      log::error("LCM {}: a {} B message on '{}' cannot be sent (channel of 1 … 63 bytes, at most 65 535 fragments)",
                 url_, bytes.size(), channel);
    return;
  }
  ++seqno_;
  // All the message's datagrams in one system call (a cloud is several).
  std::array<mmsghdr, 64> headers{};
  std::array<std::array<iovec, 3>, 64> pieces{};
  std::size_t next = 0;
  while (next < datagrams_.size()) {
    const std::size_t count = std::min(headers.size(), datagrams_.size() - next);
    for (std::size_t i = 0; i < count; ++i) {
      udpm::Datagram& d = datagrams_[next + i];
      pieces[i] = {iovec{d.header.data(), d.header_bytes},
                   iovec{const_cast<std::uint8_t*>(d.channel.data()), d.channel.size()},
                   iovec{const_cast<std::uint8_t*>(d.payload.data()), d.payload.size()}};
      headers[i] = mmsghdr{};
      headers[i].msg_hdr.msg_name = &destination_;
      headers[i].msg_hdr.msg_namelen = sizeof destination_;
      headers[i].msg_hdr.msg_iov = pieces[i].data();
      headers[i].msg_hdr.msg_iovlen = pieces[i].size();
    }
    const int sent = sendmmsg(send_fd_, headers.data(), static_cast<unsigned>(count), 0);
    if (sent <= 0) {
      if (sent < 0 && errno == EINTR) continue;
      if (send_limit_.allow(host::monotonic_ns(), suppressed))
        log::warn("LCM {}: sending '{}' ({} B): {}{}", url_, channel, bytes.size(), std::strerror(errno),
                  suppressed > 0 ? " (" + std::to_string(suppressed) + " similar suppressed)" : std::string());
      return;
    }
    next += static_cast<std::size_t>(sent);
  }
}

bool UdpmOutlet::subscribe(const std::string& channel, Handler handler) {
  if (!own_source_) return false;
  try {
    receiver_ = std::make_unique<UdpmReceiver>(url_, group_, std::vector<std::string>{channel}, own_source_);
  } catch (const std::runtime_error& e) {
    log::error("{} (the input on {})", e.what(), channel);
    return false;
  }
  handler_ = std::move(handler);
  return true;
}

int UdpmOutlet::incoming_fd() const noexcept {
  return receiver_ ? receiver_->fd() : -1;
}

void UdpmOutlet::handle_incoming() {
  if (!receiver_) return;
  receiver_->read([this](std::string_view channel, std::span<const std::uint8_t> payload) {
    if (handler_) handler_(payload, std::string(channel));
  });
}

}  // namespace trajroi::daemon
