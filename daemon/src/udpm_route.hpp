#pragma once

// Where the kernel sends an LCM group's datagrams, for one start-up line when a group that
// never leaves this host (ttl=0) is routed through an interface that cuts the clouds'
// datagrams into IP fragments (docs/lcm.md, "The group's route on one machine").
#include <optional>
#include <string>

#include "trajroi/daemon/config.hpp"

namespace trajroi::daemon {

// The route a datagram sent to the group from an unbound address takes, as `ip route get`
// reports it (the kernel's route lookup over netlink): its interface and MTU (the route's own
// mtu if it has one, else the interface's). nullopt when there is no route or netlink cannot
// be asked.
struct UdpmRoute {
  std::string interface;
  int mtu = 0;
  bool route_mtu = false;  // the MTU is the route's own (its mtu metric), not the interface's
};
[[nodiscard]] std::optional<UdpmRoute> udpm_route(const LcmGroup& group);

// IP fragments of the outlet's largest datagram (transport::udpm::kMaxDatagramBytes of UDP
// payload) through an MTU of `mtu` (RFC 791: every fragment's data but the last a multiple of
// 8 bytes); 1 when it fits whole.
[[nodiscard]] int udpm_fragments_per_datagram(int mtu) noexcept;

// The start-up line for a ttl=0 group routed where its largest datagrams are fragmented: what
// it costs and the remedy: route the group over lo, or, when it already goes over lo, take
// the small MTU off that route or raise lo's own. Empty when there is nothing to say.
[[nodiscard]] std::string udpm_route_advice(const std::string& url, const LcmGroup& group, const UdpmRoute& route);

}  // namespace trajroi::daemon
