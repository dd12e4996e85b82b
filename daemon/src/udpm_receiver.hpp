#pragma once

// A receive socket in the LCM group of a udpm:// URL, in liblcm's wire format
// (transport/lcm_udpm.hpp), for the daemon's inputs over LCM: the trajectory (UdpmOutlet) and
// pose.source lcm (LcmPoseInput). The kernel drops the datagrams of this process's own send
// socket before they are queued, so neither reads back the clouds the daemon publishes.
#include <netinet/in.h>

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "log.hpp"
#include "trajroi/daemon/config.hpp"
#include "trajroi/transport/lcm_udpm.hpp"

namespace trajroi::daemon {

class UdpmReceiver {
 public:
  using OnMessage = std::function<void(std::string_view channel, std::span<const std::uint8_t> payload)>;

  // Bound to the group's port beside every other LCM client, the group joined on the default
  // interface (as liblcm). `exclude`: the source address and port whose datagrams the kernel
  // drops (nullopt: none). Throws std::runtime_error naming the URL and the step that failed.
  UdpmReceiver(std::string url, const LcmGroup& group, std::vector<std::string> channels,
               const std::optional<sockaddr_in>& exclude);
  ~UdpmReceiver();
  UdpmReceiver(const UdpmReceiver&) = delete;
  UdpmReceiver& operator=(const UdpmReceiver&) = delete;

  [[nodiscard]] int fd() const noexcept { return fd_; }
  // Whether the kernel drops `exclude`'s datagrams (false: none given, or the filter could
  // not be attached; they are then read and left out by channel).
  [[nodiscard]] bool filters() const noexcept { return filters_; }
  // Hands every whole message on the channels that is queued now to `on_message` (at most 256
  // datagrams a call, so that a flood cannot hold the caller's thread). Datagrams that are not
  // LCM are counted and logged (rate-limited) with their sender.
  void read(const OnMessage& on_message);
  [[nodiscard]] const transport::udpm::Reassembler::Counters& counters() const noexcept {
    return reassembler_.counters();
  }

 private:
  std::string url_;
  int fd_ = -1;
  bool filters_ = false;
  transport::udpm::Reassembler reassembler_;
  std::vector<std::uint8_t> buffer_;
  log::RateLimited warn_limit_{10.0};
};

// Where the datagrams of `send_fd` come from, as the group's receivers see them: a probe sent
// from it to the group on a port of this process's own (other LCM clients do not see it),
// within `timeout_ms`, with the TTL at 0 for the probe (`ttl` restored after). nullopt when
// multicast does not come back to this host (no multicast route, a firewall, systemd's
// IPAddressAllow=).
[[nodiscard]] std::optional<sockaddr_in> udpm_own_source(int send_fd, const LcmGroup& group, int timeout_ms);

// The group's address with `port`.
[[nodiscard]] sockaddr_in udpm_group_address(const LcmGroup& group, int port);

// "a.b.c.d:port".
[[nodiscard]] std::string to_string(const sockaddr_in& address);

}  // namespace trajroi::daemon
