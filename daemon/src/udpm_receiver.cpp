#include "udpm_receiver.hpp"

#include <arpa/inet.h>
#include <linux/filter.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "pipeline.hpp"
#include "trajroi/transport/receive_buffer.hpp"

namespace trajroi::daemon {
namespace {

namespace udpm = transport::udpm;

std::string errno_text() {
  return std::strerror(errno);
}

// A classic BPF program for a UDP socket: drop the datagrams whose IPv4 source address and UDP
// source port are `self`'s, keep the rest whole. (Offsets from the network header, so that it
// does not depend on where the socket layer starts the packet.)
bool drop_datagrams_from(int fd, const sockaddr_in& self) {
  std::array<sock_filter, 7> code{{
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, static_cast<std::uint32_t>(SKF_NET_OFF + 12)),  // IPv4 source
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, ntohl(self.sin_addr.s_addr), 0, 3),            // else keep
      BPF_STMT(BPF_LDX | BPF_B | BPF_MSH, static_cast<std::uint32_t>(SKF_NET_OFF)),      // IPv4 header length
      BPF_STMT(BPF_LD | BPF_H | BPF_IND, static_cast<std::uint32_t>(SKF_NET_OFF)),       // UDP source port
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, ntohs(self.sin_port), 1, 0),                   // then drop
      BPF_STMT(BPF_RET | BPF_K, 0xFFFFFFFFu),                                            // keep, whole
      BPF_STMT(BPF_RET | BPF_K, 0),                                                      // drop
  }};
  const sock_fprog program{static_cast<unsigned short>(code.size()), code.data()};
  return setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &program, sizeof program) == 0;
}

}  // namespace

std::optional<sockaddr_in> udpm_own_source(int send_fd, const LcmGroup& group, int timeout_ms) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return std::nullopt;
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_addr.s_addr = htonl(INADDR_ANY);
  socklen_t length = sizeof local;
  ip_mreq membership{};
  std::optional<sockaddr_in> source;
  if (inet_pton(AF_INET, group.address.c_str(), &membership.imr_multiaddr) == 1 &&
      bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof local) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length) == 0 &&
      setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership) == 0) {
    const sockaddr_in to = udpm_group_address(group, ntohs(local.sin_port));
    const unsigned char probe_ttl = 0;
    const auto ttl = static_cast<unsigned char>(group.ttl);
    (void)setsockopt(send_fd, IPPROTO_IP, IP_MULTICAST_TTL, &probe_ttl, sizeof probe_ttl);
    const std::array<char, 13> probe{'t', 'r', 'a', 'j', 'r', 'o', 'i', ' ', 'p', 'r', 'o', 'b', 'e'};
    const bool sent = sendto(send_fd, probe.data(), probe.size(), 0, reinterpret_cast<const sockaddr*>(&to),
                             sizeof to) == static_cast<ssize_t>(probe.size());
    (void)setsockopt(send_fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
    pollfd p{fd, POLLIN, 0};
    std::array<char, 64> received{};
    sockaddr_in from{};
    socklen_t from_length = sizeof from;
    if (sent && poll(&p, 1, timeout_ms) == 1 &&
        recvfrom(fd, received.data(), received.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_length) ==
            static_cast<ssize_t>(probe.size()) &&
        std::memcmp(received.data(), probe.data(), probe.size()) == 0) {
      source = from;
    }
  }
  close(fd);
  return source;
}

sockaddr_in udpm_group_address(const LcmGroup& group, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  (void)inet_pton(AF_INET, group.address.c_str(), &a.sin_addr);
  return a;
}

std::string to_string(const sockaddr_in& address) {
  std::array<char, INET_ADDRSTRLEN> text{};
  (void)inet_ntop(AF_INET, &address.sin_addr, text.data(), text.size());
  return std::string(text.data()) + ":" + std::to_string(ntohs(address.sin_port));
}

UdpmReceiver::UdpmReceiver(std::string url, const LcmGroup& group, std::vector<std::string> channels,
                           const std::optional<sockaddr_in>& exclude)
    : url_(std::move(url)), reassembler_(std::move(channels)), buffer_(udpm::kMaxDatagramBytes + 1) {
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0) throw std::runtime_error("LCM " + url_ + ": cannot open a UDP socket: " + errno_text());
  const int reuse = 1;
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_port = htons(static_cast<std::uint16_t>(group.port));
  local.sin_addr.s_addr = htonl(INADDR_ANY);
  ip_mreq membership{};
  membership.imr_multiaddr = udpm_group_address(group, group.port).sin_addr;
  membership.imr_interface.s_addr = htonl(INADDR_ANY);
  const auto fail = [this](const std::string& what) {
    const std::string why = errno_text();
    close(fd_);
    throw std::runtime_error("LCM " + url_ + ": " + what + ": " + why);
  };
  // Shared with every other LCM client on the port. The filter goes on before the membership,
  // so no excluded datagram is ever queued.
  if (setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &reuse, sizeof reuse) != 0 ||
      bind(fd_, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0) {
    fail("cannot bind port " + std::to_string(group.port));
  }
  if (group.recv_buf_size > 0) {
    const transport::ReceiveBuffer buffer = transport::set_receive_buffer(fd_, group.recv_buf_size);
    if (buffer.capped()) log::warn("{}", transport::describe_capped("LCM " + url_, buffer));
  }
  if (exclude) {
    filters_ = drop_datagrams_from(fd_, *exclude);
    if (!filters_)
      log::warn(
          "LCM {}: the filter that keeps this process's own datagrams ({}) out of its receive socket "
          "could not be attached ({}); they are read and left out",
          url_, to_string(*exclude), errno_text());
  }
  if (setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership) != 0)
    fail("cannot join " + group.address);
}

UdpmReceiver::~UdpmReceiver() {
  close(fd_);
}

void UdpmReceiver::read(const OnMessage& on_message) {
  for (int n = 0; n < 256; ++n) {
    sockaddr_in from{};
    socklen_t from_length = sizeof from;
    const ssize_t got =
        recvfrom(fd_, buffer_.data(), buffer_.size(), MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&from), &from_length);
    std::uint64_t suppressed = 0;
    if (got < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK && warn_limit_.allow(host::monotonic_ns(), suppressed))
        log::warn("LCM {}: receiving: {}", url_, errno_text());
      return;  // nothing more queued (or the next poll says again)
    }
    const std::uint64_t sender = static_cast<std::uint64_t>(ntohl(from.sin_addr.s_addr)) << 16 | ntohs(from.sin_port);
    udpm::Reassembler::Message message;
    const auto verdict = reassembler_.accept(
        sender, std::span<const std::uint8_t>(buffer_.data(), static_cast<std::size_t>(got)), message);
    if (verdict == udpm::Reassembler::Verdict::kMessage) {
      on_message(message.channel, message.payload);
    } else if (verdict == udpm::Reassembler::Verdict::kMalformed &&
               warn_limit_.allow(host::monotonic_ns(), suppressed)) {
      log::warn("LCM {}: a {} B datagram from {} is not an LCM message or fragment ({} malformed so far)", url_, got,
                to_string(from), reassembler_.counters().malformed);
    }
  }
}

}  // namespace trajroi::daemon
