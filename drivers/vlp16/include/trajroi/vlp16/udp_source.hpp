#pragma once

// Live Velodyne packets from UDP sockets (Linux): one for data (2368), one for position
// packets (8308), received in recvmmsg batches with kernel receive timestamps. An I/O
// adapter, kept out of the pure decoder's target.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "trajroi/vlp16/packet_source.hpp"

struct mmsghdr;  // <sys/socket.h>, included by the implementation only
struct iovec;
struct sockaddr_in;

namespace trajroi::vlp16 {

struct UdpOptions {
  std::string bind_address = "0.0.0.0";  // IPv4 address to bind both sockets to
  std::uint16_t data_port = kDataPort;   // 0: the kernel chooses (tests)
  std::uint16_t position_port = kPositionPort;
  bool open_position_socket = true;
  int receive_buffer_bytes = 4 << 20;  // SO_RCVBUF asked for; see granted_receive_buffer_bytes()
  std::size_t batch = 32;              // datagrams per recvmmsg
  // When set (an IPv4 address), datagrams from any other source address are dropped and
  // counted (rejected_sources()); empty accepts every sender.
  std::string sensor_address;
  // The ports are this process's alone: a second bind to them fails (EADDRINUSE), so two
  // daemons can never split one sensor's stream between them. `share_ports` (SO_REUSEADDR)
  // is for multicast set-ups where several readers receive the same datagrams.
  bool share_ports = false;
};

class UdpSource final : public PacketSource {
 public:
  // Binds the sockets. Throws std::runtime_error naming the address, port and errno text
  // when a socket cannot be created or bound, or the address is not an IPv4 address.
  explicit UdpSource(UdpOptions options);
  ~UdpSource() override;
  UdpSource(const UdpSource&) = delete;
  UdpSource& operator=(const UdpSource&) = delete;

  Next next(Datagram& datagram, std::chrono::milliseconds timeout) override;
  [[nodiscard]] const std::string& error() const noexcept override { return error_; }

  // What the kernel granted for the data socket's receive buffer (Linux reports twice the
  // usable size). Below the request, net.core.rmem_max is too small: the caller warns.
  [[nodiscard]] int granted_receive_buffer_bytes() const noexcept { return granted_; }
  [[nodiscard]] int requested_receive_buffer_bytes() const noexcept { return options_.receive_buffer_bytes; }
  // A message for the caller to log when the kernel granted less than asked, else empty.
  [[nodiscard]] std::string receive_buffer_warning() const;
  // The ports actually bound (useful with port 0, which lets the kernel choose).
  [[nodiscard]] std::uint16_t data_port() const noexcept { return sockets_[0].port; }
  [[nodiscard]] std::uint16_t position_port() const noexcept { return sockets_[1].port; }
  // Datagrams truncated because they were longer than a Velodyne packet buffer.
  [[nodiscard]] std::uint64_t truncated() const noexcept { return truncated_; }
  // Datagrams the kernel dropped because a socket's receive buffer was full (SO_RXQ_OVFL, as
  // last reported with a received datagram), both sockets.
  [[nodiscard]] std::uint64_t kernel_drops() const noexcept {
    return std::uint64_t{sockets_[0].kernel_drops} + sockets_[1].kernel_drops;
  }
  // Datagrams dropped because they came from an address other than UdpOptions::sensor_address.
  [[nodiscard]] std::uint64_t rejected_sources() const noexcept { return rejected_sources_; }

 private:
  struct Socket {
    int fd = -1;
    std::uint16_t port = 0;
    // One receive batch: buffers, the headers pointing at them, and control space for the
    // timestamps; `count` received, `next` the first not yet handed out.
    std::vector<std::uint8_t> buffers;
    std::vector<std::uint8_t> control;
    std::vector<mmsghdr> headers;
    std::vector<iovec> iovecs;
    std::vector<sockaddr_in> senders;
    std::size_t count = 0;
    std::size_t next = 0;
    std::uint32_t kernel_drops = 0;
  };
  void open_socket(Socket& socket, std::uint16_t port, bool data);
  bool deliver(Socket& socket, Datagram& datagram);
  bool receive_batch(Socket& socket);

  UdpOptions options_;
  Socket sockets_[2];
  int granted_ = 0;
  std::uint64_t truncated_ = 0;
  std::uint64_t rejected_sources_ = 0;
  std::uint32_t sensor_address_ = 0;  // network byte order; 0: any sender
  std::size_t turn_ = 0;              // alternate between sockets so neither starves
  std::string error_;
};

}  // namespace trajroi::vlp16
