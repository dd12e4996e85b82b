#include "trajroi/vlp16/udp_source.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace trajroi::vlp16 {
namespace {

// Big enough for any Velodyne datagram (1206 or 512 bytes) and an Ethernet MTU.
constexpr std::size_t kBufferBytes = 1536;
// A receive timestamp and the socket's drop counter (SO_RXQ_OVFL).
constexpr std::size_t kControlBytes = CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t));

std::int64_t realtime_now_ns() noexcept {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

}  // namespace

UdpSource::UdpSource(UdpOptions options) : options_(std::move(options)) {
  if (options_.batch == 0) options_.batch = 1;
  if (!options_.sensor_address.empty()) {
    in_addr sensor{};
    if (inet_pton(AF_INET, options_.sensor_address.c_str(), &sensor) != 1 || sensor.s_addr == 0) {
      throw std::runtime_error("UDP sensor address '" + options_.sensor_address + "' is not an IPv4 host address");
    }
    sensor_address_ = sensor.s_addr;
  }
  open_socket(sockets_[0], options_.data_port, true);
  if (options_.open_position_socket) open_socket(sockets_[1], options_.position_port, false);
}

UdpSource::~UdpSource() {
  for (Socket& socket : sockets_) {
    if (socket.fd >= 0) ::close(socket.fd);
  }
}

void UdpSource::open_socket(Socket& socket, std::uint16_t port, bool data) {
  const std::string where = options_.bind_address + ":" + std::to_string(port);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  if (inet_pton(AF_INET, options_.bind_address.c_str(), &address.sin_addr) != 1) {
    throw std::runtime_error("UDP bind address '" + options_.bind_address + "' is not an IPv4 address");
  }
  socket.fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (socket.fd < 0) throw std::runtime_error("UDP " + where + ": socket: " + std::strerror(errno));
  const int on = 1;
  if (options_.share_ports && setsockopt(socket.fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) != 0) {
    throw std::runtime_error("UDP " + where + ": SO_REUSEADDR: " + std::strerror(errno));
  }
  if (setsockopt(socket.fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) {
    throw std::runtime_error("UDP " + where + ": SO_TIMESTAMPNS: " + std::strerror(errno));
  }
  // The kernel's count of datagrams it dropped for a full receive buffer, with each datagram.
  if (setsockopt(socket.fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) != 0) {
    throw std::runtime_error("UDP " + where + ": SO_RXQ_OVFL: " + std::strerror(errno));
  }
  if (data) {
    // SO_RCVBUFFORCE passes net.core.rmem_max when the process may (CAP_NET_ADMIN).
    const int& bytes = options_.receive_buffer_bytes;
    if (setsockopt(socket.fd, SOL_SOCKET, SO_RCVBUFFORCE, &bytes, sizeof bytes) != 0) {
      setsockopt(socket.fd, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes);
    }
    socklen_t length = sizeof granted_;
    getsockopt(socket.fd, SOL_SOCKET, SO_RCVBUF, &granted_, &length);
  }
  if (::bind(socket.fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const bool errno_in_use = errno == EADDRINUSE;
    const std::string reason = std::strerror(errno);
    ::close(socket.fd);
    socket.fd = -1;
    const bool in_use = errno_in_use;
    throw std::runtime_error("UDP " + where + ": bind: " + reason +
                             (in_use ? " (another process receives on this port; lidar.share_ports: true lets "
                                       "several readers share it)"
                                     : ""));
  }
  sockaddr_in bound{};
  socklen_t bound_length = sizeof bound;
  getsockname(socket.fd, reinterpret_cast<sockaddr*>(&bound), &bound_length);
  socket.port = ntohs(bound.sin_port);

  const std::size_t batch = options_.batch;
  socket.buffers.assign(batch * kBufferBytes, 0);
  socket.control.assign(batch * kControlBytes, 0);
  socket.headers.assign(batch, mmsghdr{});
  socket.iovecs.assign(batch, iovec{});
  socket.senders.assign(batch, sockaddr_in{});
}

std::string UdpSource::receive_buffer_warning() const {
  if (granted_ / 2 >= options_.receive_buffer_bytes) return {};
  return "UDP port " + std::to_string(sockets_[0].port) + ": SO_RCVBUF " + std::to_string(granted_ / 2) +
         " bytes granted, " + std::to_string(options_.receive_buffer_bytes) +
         " asked for; raise net.core.rmem_max (sysctl) or give the service CAP_NET_ADMIN, or packets may be "
         "dropped under load";
}

bool UdpSource::receive_batch(Socket& socket) {
  for (std::size_t i = 0; i < options_.batch; ++i) {
    socket.iovecs[i] = iovec{socket.buffers.data() + i * kBufferBytes, kBufferBytes};
    msghdr& header = socket.headers[i].msg_hdr;
    header = msghdr{};
    header.msg_iov = &socket.iovecs[i];
    header.msg_iovlen = 1;
    header.msg_name = &socket.senders[i];
    header.msg_namelen = sizeof(sockaddr_in);
    header.msg_control = socket.control.data() + i * kControlBytes;
    header.msg_controllen = kControlBytes;
  }
  const int received =
      recvmmsg(socket.fd, socket.headers.data(), static_cast<unsigned>(options_.batch), MSG_DONTWAIT, nullptr);
  if (received < 0) {
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      error_ = "UDP port " + std::to_string(socket.port) + ": recvmmsg: " + std::strerror(errno);
    }
    return false;
  }
  socket.count = static_cast<std::size_t>(received);
  socket.next = 0;
  return received > 0;
}

bool UdpSource::deliver(Socket& socket, Datagram& datagram) {
  if (sensor_address_ != 0) {
    while (socket.next < socket.count && socket.senders[socket.next].sin_addr.s_addr != sensor_address_) {
      ++socket.next;
      ++rejected_sources_;
    }
  }
  if (socket.next >= socket.count) return false;
  const std::size_t i = socket.next++;
  const mmsghdr& message = socket.headers[i];
  if ((message.msg_hdr.msg_flags & MSG_TRUNC) != 0) ++truncated_;
  datagram.payload = std::span<const std::uint8_t>(socket.buffers.data() + i * kBufferBytes,
                                                   std::min<std::size_t>(message.msg_len, kBufferBytes));
  datagram.destination_port = socket.port;
  const sockaddr_in& from = socket.senders[i];
  datagram.sender = (static_cast<std::uint64_t>(ntohl(from.sin_addr.s_addr)) << 16) | ntohs(from.sin_port);
  datagram.receive_time_ns = 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&message.msg_hdr); c != nullptr;
       c = CMSG_NXTHDR(const_cast<msghdr*>(&message.msg_hdr), c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec stamp{};
      std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
      datagram.receive_time_ns = static_cast<std::int64_t>(stamp.tv_sec) * 1'000'000'000 + stamp.tv_nsec;
    } else if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
      std::uint32_t dropped = 0;
      std::memcpy(&dropped, CMSG_DATA(c), sizeof dropped);
      socket.kernel_drops = dropped;  // cumulative since the socket opened
    }
  }
  if (datagram.receive_time_ns == 0) datagram.receive_time_ns = realtime_now_ns();
  return true;
}

PacketSource::Next UdpSource::next(Datagram& datagram, std::chrono::milliseconds timeout) {
  error_.clear();
  const std::size_t sockets = sockets_[1].fd >= 0 ? 2 : 1;
  // Hand out what an earlier batch left, taking the sockets in turn.
  for (std::size_t k = 0; k < sockets; ++k) {
    Socket& socket = sockets_[(turn_ + k) % sockets];
    if (deliver(socket, datagram)) {
      turn_ = (turn_ + k + 1) % sockets;
      return Next::kDatagram;
    }
  }
  pollfd fds[2] = {{sockets_[0].fd, POLLIN, 0}, {sockets_[1].fd, POLLIN, 0}};
  const long long wait_ms = timeout.count() > 1'000'000 ? 1'000'000 : timeout.count();
  const int ready = ::poll(fds, sockets, static_cast<int>(wait_ms < 0 ? 0 : wait_ms));
  if (ready < 0) {
    if (errno == EINTR) return Next::kTimeout;
    error_ = std::string("UDP poll: ") + std::strerror(errno);
    return Next::kError;
  }
  for (std::size_t k = 0; k < sockets; ++k) {
    if ((fds[k].revents & POLLIN) != 0) receive_batch(sockets_[k]);
  }
  if (!error_.empty()) return Next::kError;
  for (std::size_t k = 0; k < sockets; ++k) {
    Socket& socket = sockets_[(turn_ + k) % sockets];
    if (deliver(socket, datagram)) {
      turn_ = (turn_ + k + 1) % sockets;
      return Next::kDatagram;
    }
  }
  return Next::kTimeout;
}

}  // namespace trajroi::vlp16
