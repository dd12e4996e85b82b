#pragma once

// The receive buffer an LCM subscriber asks for (udpm://…?recv_buf_size=N), taken where the
// process may, and said plainly where the kernel capped it.
//
// A socket's SO_RCVBUF is capped by net.core.rmem_max (212 992 B on a stock kernel: a fifth
// of one dual-return sweep), silently: liblcm prints a warning to stderr at best, and a
// subscriber then loses clouds whenever it falls behind for a few sweeps. SO_RCVBUFFORCE passes
// the cap for a process with CAP_NET_ADMIN (root). liblcm does not hand out its receive socket,
// so for an lcm::LCM the socket is found among the process's own file descriptors: the UDP
// socket bound to the group's port.
#include <cstdint>
#include <string>

namespace trajroi::transport {

struct ReceiveBuffer {
  int asked_bytes = 0;    // what the URL asked for
  int granted_bytes = 0;  // what the socket holds now (the kernel's figure halved: its usable size)
  bool forced = false;    // SO_RCVBUFFORCE took it (past net.core.rmem_max)
  bool found = false;     // a socket was found to set
  [[nodiscard]] bool capped() const noexcept { return found && granted_bytes < asked_bytes; }
};

// Sets `fd`'s receive buffer to `bytes`: SO_RCVBUFFORCE where permitted, else SO_RCVBUF.
ReceiveBuffer set_receive_buffer(int fd, int bytes);

// The same for every UDP socket of this process bound to `port` (liblcm's receive socket for a
// udpm:// group on that port, once it has subscribed and asked for its file descriptor).
ReceiveBuffer set_udp_receive_buffers(std::uint16_t port, int bytes);

// The recv_buf_size of a udpm:// URL (0 when it has none), and its port (7667 when it gives
// none). False for a URL that is not udpm://.
bool udpm_receive_options(const std::string& url, int& recv_buf_size, std::uint16_t& port);

// The URL without its recv_buf_size= option. liblcm sets that buffer itself with SO_RCVBUF
// only, which the kernel caps at net.core.rmem_max without a word: a subscriber opens the URL
// without it and asks with set_udp_receive_buffers (past the cap where it may).
[[nodiscard]] std::string without_receive_buffer(const std::string& url);

// One line for a capped buffer, naming what to do about it ("" when it was not capped):
// "<who>: the kernel capped the LCM receive buffer at 208 KiB of the 8192 KiB asked for
//  (net.core.rmem_max); clouds may be lost. Run as root, or apply the sysctl drop-in …".
[[nodiscard]] std::string describe_capped(const std::string& who, const ReceiveBuffer& buffer);

}  // namespace trajroi::transport
