#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>

#include "outlet.hpp"
#include "trajroi/daemon/config.hpp"
#include "trajroi/transport/lcm_subscribe.hpp"

namespace trajroi::daemon {
namespace {

// Whether a datagram this process sends to the group comes back to it, within `timeout_ms`:
// what LCM's self test finds out too, but bounded and on a port of its own (LCM's retries for
// seconds on every receive call, and other LCM clients would see the probe).
bool multicast_comes_back(const LcmGroup& group, int timeout_ms) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_ANY);
  socklen_t length = sizeof address;
  ip_mreq membership{};
  bool back = false;
  if (inet_pton(AF_INET, group.address.c_str(), &membership.imr_multiaddr) == 1 &&
      bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0 &&
      setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership) == 0) {
    const unsigned char ttl = 0;
    (void)setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
    address.sin_addr = membership.imr_multiaddr;
    const std::array<char, 13> probe{'t', 'r', 'a', 'j', 'r', 'o', 'i', ' ', 'p', 'r', 'o', 'b', 'e'};
    if (sendto(fd, probe.data(), probe.size(), 0, reinterpret_cast<const sockaddr*>(&address), sizeof address) ==
        static_cast<ssize_t>(probe.size())) {
      pollfd p{fd, POLLIN, 0};
      std::array<char, 64> received{};
      back = poll(&p, 1, timeout_ms) == 1 &&
             recv(fd, received.data(), received.size(), 0) == static_cast<ssize_t>(probe.size());
    }
  }
  close(fd);
  return back;
}

}  // namespace

LcmOutlet::LcmOutlet(const std::string& url) : lcm_(std::make_unique<lcm::LCM>(url)) {
  if (!lcm_->good()) {
    throw std::runtime_error("LCM: cannot open '" + url + "' (is there a route for multicast? try ?ttl=0 on loopback)");
  }
  const std::optional<LcmGroup> group = lcm_multicast_group(url);
  receives_ = !group || multicast_comes_back(*group, 500);
}

LcmOutlet::~LcmOutlet() = default;

void LcmOutlet::publish(const std::string& channel, std::span<const std::uint8_t> bytes) {
  (void)lcm_->publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
}

bool LcmOutlet::subscribe(const std::string& channel, Handler handler) {
  if (!receives_) return false;
  handler_ = std::move(handler);
  return transport::subscribe_raw<&LcmOutlet::on_message>(*lcm_, channel, this) != nullptr;
}

int LcmOutlet::incoming_fd() const noexcept {
  return receives_ ? lcm_->getFileno() : -1;
}

void LcmOutlet::handle_incoming() {
  (void)lcm_->handleTimeout(0);
}

void LcmOutlet::on_message(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
  if (handler_)
    handler_(std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size), channel);
}

}  // namespace trajroi::daemon
