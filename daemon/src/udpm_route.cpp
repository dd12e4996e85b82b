#include "udpm_route.hpp"

#include <arpa/inet.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "trajroi/transport/lcm_udpm.hpp"

namespace trajroi::daemon {
namespace {

// A netlink attribute's header and where the next one begins (RTA_ALIGN), read with memcpy
// from the reply's bytes.
struct Attribute {
  std::uint16_t type = 0;
  std::size_t payload = 0;  // offset of its payload
  std::size_t length = 0;   // of its payload
  std::size_t next = 0;
};

std::optional<Attribute> attribute_at(const std::uint8_t* bytes, std::size_t at, std::size_t end) {
  rtattr header{};
  if (at + sizeof header > end) return std::nullopt;
  std::memcpy(&header, bytes + at, sizeof header);
  if (header.rta_len < sizeof header || at + header.rta_len > end) return std::nullopt;
  return Attribute{header.rta_type, at + sizeof header, header.rta_len - sizeof header,
                   at + ((header.rta_len + 3U) & ~std::size_t{3})};
}

std::uint32_t read_u32(const std::uint8_t* bytes, const Attribute& a) {
  std::uint32_t value = 0;
  if (a.length >= sizeof value) std::memcpy(&value, bytes + a.payload, sizeof value);
  return value;
}

// The kernel's answer to RTM_GETROUTE for `group` (as `ip route get`): the output interface's
// index and the route's own MTU metric (0: none).
std::optional<std::pair<std::uint32_t, std::uint32_t>> ask_route(const in_addr& group) {
  const int fd = socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
  if (fd < 0) return std::nullopt;
  struct Request {
    nlmsghdr header;
    rtmsg route;
    rtattr destination;
    in_addr address;
  } request{};
  request.header.nlmsg_len = sizeof request;
  request.header.nlmsg_type = RTM_GETROUTE;
  request.header.nlmsg_flags = NLM_F_REQUEST;
  request.header.nlmsg_seq = 1;
  request.route.rtm_family = AF_INET;
  request.route.rtm_dst_len = 32;
  request.destination.rta_len = sizeof request.destination + sizeof request.address;
  request.destination.rta_type = RTA_DST;
  request.address = group;
  std::array<std::uint8_t, 4096> reply{};
  ssize_t received = -1;
  pollfd p{fd, POLLIN, 0};
  if (send(fd, &request, sizeof request, 0) == static_cast<ssize_t>(sizeof request) && poll(&p, 1, 500) == 1)
    received = recv(fd, reply.data(), reply.size(), 0);
  close(fd);
  if (received < static_cast<ssize_t>(sizeof(nlmsghdr))) return std::nullopt;
  const auto end = static_cast<std::size_t>(received);
  nlmsghdr header{};
  std::memcpy(&header, reply.data(), sizeof header);
  if (header.nlmsg_type != RTM_NEWROUTE || header.nlmsg_len > end) return std::nullopt;
  std::uint32_t oif = 0;
  std::uint32_t mtu = 0;
  constexpr std::size_t kFirst = NLMSG_HDRLEN + ((sizeof(rtmsg) + 3U) & ~std::size_t{3});
  for (auto a = attribute_at(reply.data(), kFirst, header.nlmsg_len); a;
       a = attribute_at(reply.data(), a->next, header.nlmsg_len)) {
    if (a->type == RTA_OIF) oif = read_u32(reply.data(), *a);
    if (a->type != RTA_METRICS) continue;
    const std::size_t metrics_end = a->payload + a->length;
    for (auto m = attribute_at(reply.data(), a->payload, metrics_end); m;
         m = attribute_at(reply.data(), m->next, metrics_end))
      if (m->type == RTAX_MTU) mtu = read_u32(reply.data(), *m);
  }
  if (oif == 0) return std::nullopt;
  return std::pair{oif, mtu};
}

}  // namespace

std::optional<UdpmRoute> udpm_route(const LcmGroup& group) {
  in_addr address{};
  if (inet_pton(AF_INET, group.address.c_str(), &address) != 1) return std::nullopt;
  const auto route = ask_route(address);
  if (!route) return std::nullopt;
  std::array<char, IF_NAMESIZE> name{};
  if (if_indextoname(route->first, name.data()) == nullptr) return std::nullopt;
  UdpmRoute r{name.data(), static_cast<int>(route->second), route->second != 0};
  if (r.mtu == 0) {  // the interface's own
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return std::nullopt;
    ifreq request{};
    std::memcpy(request.ifr_name, name.data(), sizeof request.ifr_name);
    const bool known = ioctl(fd, SIOCGIFMTU, &request) == 0;
    close(fd);
    if (!known) return std::nullopt;
    r.mtu = request.ifr_mtu;
  }
  return r;
}

int udpm_fragments_per_datagram(int mtu) noexcept {
  constexpr int kIpHeader = 20;
  constexpr int kUdpBytes = static_cast<int>(transport::udpm::kMaxDatagramBytes) + 8;  // with UDP's header
  if (kUdpBytes + kIpHeader <= mtu) return 1;
  const int per_fragment = (mtu - kIpHeader) / 8 * 8;
  if (per_fragment <= 0) return 0;
  return (kUdpBytes + per_fragment - 1) / per_fragment;
}

std::string udpm_route_advice(const std::string& url, const LcmGroup& group, const UdpmRoute& route) {
  const int fragments = udpm_fragments_per_datagram(route.mtu);
  if (group.ttl != 0 || fragments <= 1) return {};
  std::string remedy;
  if (route.interface != "lo") {
    remedy = "when every subscriber runs here, route the group over lo (ip link set lo multicast on; ip route add " +
             group.address + "/32 dev lo";
  } else if (route.route_mtu) {
    remedy = "the route over lo sets that MTU itself: make it again without mtu (ip route get " + group.address +
             " shows it; ip route replace <its prefix> dev lo";
  } else {
    remedy = "lo's own MTU is that small: give it back its 65536 (ip link set lo mtu 65536";
  }
  return "LCM " + url + ": ttl=0 keeps the datagrams on this host, but the group's route goes through " +
         route.interface + " (MTU " + std::to_string(route.mtu) + "): each 64 KB datagram of a cloud is cut into " +
         std::to_string(fragments) + " IP fragments, each copied and checksummed; " + remedy + "; docs/lcm.md)";
}

}  // namespace trajroi::daemon
