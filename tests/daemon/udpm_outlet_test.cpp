// trajroid's LCM outlet for udpm:// URLs against liblcm on loopback (a private port of the
// group): liblcm's messages reach it, its messages reach liblcm, identical; its own datagrams
// never come back to it, while another socket of the same process receives them.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "outlet.hpp"
#include "trajroi/transport/lcm_subscribe.hpp"
#include "udpm_route.hpp"

namespace {

using trajroi::daemon::UdpmOutlet;
using Received = std::vector<std::pair<std::string, std::vector<std::uint8_t>>>;

int free_port() {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  socklen_t length = sizeof a;
  (void)bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  (void)getsockname(fd, reinterpret_cast<sockaddr*>(&a), &length);
  close(fd);
  return ntohs(a.sin_port);
}

std::vector<std::uint8_t> bytes_of(std::size_t n, std::uint8_t seed) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = static_cast<std::uint8_t>(i * 31 + seed);
  return v;
}

// A socket closed when the test leaves, by any path.
struct Socket {
  int fd;
  explicit Socket(int f) : fd(f) {}
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  ~Socket() {
    if (fd >= 0) close(fd);
  }
};

// One datagram to the group on `port`, TTL 0, from a plain socket (neither liblcm's nor the
// outlet's): whether it was sent.
bool send_to_group(int port, std::string_view text) {
  const Socket plain(socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  const unsigned char ttl = 0;
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  inet_pton(AF_INET, "239.255.76.67", &to.sin_addr);
  return setsockopt(plain.fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) == 0 &&
         sendto(plain.fd, text.data(), text.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) ==
             static_cast<ssize_t>(text.size());
}

// Runs `outlet`'s incoming handling until `done` or `timeout`.
void pump(UdpmOutlet& outlet, const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!done() && std::chrono::steady_clock::now() < end) {
    pollfd p{outlet.incoming_fd(), POLLIN, 0};
    if (poll(&p, 1, 20) == 1) outlet.handle_incoming();
  }
}

struct Listener {
  Received messages;
  void on_message(const lcm::ReceiveBuffer* b, const std::string& channel) {
    const auto* data = static_cast<const std::uint8_t*>(b->data);
    messages.emplace_back(channel, std::vector<std::uint8_t>(data, data + b->data_size));
  }
};

}  // namespace

TEST(UdpmOutlet, TalksWithLiblcmBothWaysAndNeverReadsItsOwnDatagrams) {
  // A 300 kB message arrives as five datagrams at once: room for them (as the daemon's tests'
  // URL gives; the kernel's default may be smaller).
  const int port = free_port();
  const std::string url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
  const auto group = trajroi::daemon::lcm_multicast_group(url);
  ASSERT_TRUE(group.has_value());
  EXPECT_EQ(group->port, port);
  EXPECT_EQ(group->ttl, 0);
  EXPECT_EQ(group->recv_buf_size, 4194304);
  UdpmOutlet outlet(url, *group);
  Received got;
  const auto keep = [](Received& into) {
    return [&into](std::span<const std::uint8_t> bytes, const std::string& channel) {
      into.emplace_back(channel, std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
    };
  };
  ASSERT_TRUE(outlet.subscribe("IN", keep(got))) << "multicast does not come back on this host";
  ASSERT_TRUE(outlet.own_source().has_value());
  EXPECT_TRUE(outlet.filters_own());
  ASSERT_GE(outlet.incoming_fd(), 0);

  lcm::LCM listener_lcm(url);
  Listener listener;
  ASSERT_NE(trajroi::transport::subscribe_raw<&Listener::on_message>(listener_lcm, ".*", &listener), nullptr);
  lcm::LCM publisher(url);
  const std::vector<std::uint8_t> small = bytes_of(100, 1);
  const std::vector<std::uint8_t> big = bytes_of(300000, 2);

  // liblcm → the outlet: short and fragmented, the other channel left out.
  publisher.publish("IN", small.data(), static_cast<unsigned>(small.size()));
  publisher.publish("OTHER", small.data(), static_cast<unsigned>(small.size()));
  publisher.publish("IN", big.data(), static_cast<unsigned>(big.size()));
  pump(
      outlet, [&] { return got.size() >= 2; }, std::chrono::seconds(3));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], (std::pair<std::string, std::vector<std::uint8_t>>{"IN", small}));
  EXPECT_EQ(got[1], (std::pair<std::string, std::vector<std::uint8_t>>{"IN", big}));

  // The outlet → liblcm, identical; the outlet itself hears nothing of it, not even on the
  // channel it subscribed to.
  outlet.publish("IN", big);
  outlet.publish("OUT", small);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (listener.messages.size() < 5 && std::chrono::steady_clock::now() < deadline)
    (void)listener_lcm.handleTimeout(50);
  ASSERT_EQ(listener.messages.size(), 5u);
  EXPECT_EQ(listener.messages[3], (std::pair<std::string, std::vector<std::uint8_t>>{"IN", big}));
  EXPECT_EQ(listener.messages[4], (std::pair<std::string, std::vector<std::uint8_t>>{"OUT", small}));
  pump(
      outlet, [] { return false; }, std::chrono::milliseconds(300));
  EXPECT_EQ(got.size(), 2u) << "the outlet read back its own message";

  // The filter names the sender, not the channel: a second outlet of this process hears the
  // first. Garbage in the group is dropped, and what follows it still arrives.
  UdpmOutlet second(url, *group);
  Received second_got;
  ASSERT_TRUE(second.subscribe("IN", keep(second_got)));
  constexpr char kGarbage[] = "LC03 not really a fragment";
  ASSERT_TRUE(send_to_group(port, std::string_view(kGarbage, sizeof kGarbage)));
  outlet.publish("IN", small);
  pump(
      second, [&] { return !second_got.empty(); }, std::chrono::seconds(3));
  ASSERT_EQ(second_got.size(), 1u);
  EXPECT_EQ(second_got[0], (std::pair<std::string, std::vector<std::uint8_t>>{"IN", small}));
}

TEST(UdpmOutlet, MakeOutletTakesUdpmItselfAndTheOtherProvidersThroughLiblcm) {
  const std::string url = "udpm://239.255.76.67:" + std::to_string(free_port()) + "?ttl=0";
  EXPECT_NE(dynamic_cast<UdpmOutlet*>(trajroi::daemon::make_outlet(url).get()), nullptr);
  EXPECT_NE(dynamic_cast<trajroi::daemon::LcmOutlet*>(trajroi::daemon::make_outlet("memq://").get()), nullptr);
}

TEST(UdpmOutlet, AnInputOverLcmLeavesOutTheOutletsDatagramsAndHearsOthers) {
  // pose.source lcm's receiver, given the outlet's source as trajroid gives it.
  const std::string url = "udpm://239.255.76.67:" + std::to_string(free_port()) + "?ttl=0";
  const auto group = trajroi::daemon::lcm_multicast_group(url);
  ASSERT_TRUE(group.has_value());
  UdpmOutlet outlet(url, *group);
  ASSERT_TRUE(outlet.own_source().has_value()) << "multicast does not come back on this host";
  trajroi::daemon::UdpmReceiver input(url, *group, {"POSE"}, outlet.own_source());
  EXPECT_TRUE(input.filters());
  lcm::LCM localization(url);
  const std::vector<std::uint8_t> own = bytes_of(80, 3);
  const std::vector<std::uint8_t> theirs = bytes_of(67, 4);
  outlet.publish("POSE", own);
  localization.publish("POSE", theirs.data(), static_cast<unsigned>(theirs.size()));
  Received got;
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(700);
  while (std::chrono::steady_clock::now() < end) {
    pollfd p{input.fd(), POLLIN, 0};
    if (poll(&p, 1, 20) == 1)
      input.read([&](std::string_view channel, std::span<const std::uint8_t> payload) {
        got.emplace_back(std::string(channel), std::vector<std::uint8_t>(payload.begin(), payload.end()));
      });
  }
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], (std::pair<std::string, std::vector<std::uint8_t>>{"POSE", theirs}));
}

// The start-up line about the group's route (its live test: tests/daemon/lcm_route_test.sh,
// against the kernel's own fragment count in a network namespace).
TEST(UdpmRoute, FragmentsPerDatagramAreThoseRfc791Cuts) {
  using trajroi::daemon::udpm_fragments_per_datagram;
  // 65 507 B of LCM datagram + 8 B of UDP header = 65 515 B; each fragment carries the MTU
  // less the 20 B IP header, rounded down to a multiple of 8.
  EXPECT_EQ(udpm_fragments_per_datagram(1500), 45);  // 1 480 B each: 44 of them hold 65 120
  EXPECT_EQ(udpm_fragments_per_datagram(1400), 48);  // 1 376 B each: 47 hold 64 672
  EXPECT_EQ(udpm_fragments_per_datagram(9000), 8);   // 8 976 B each: 7 hold 62 832
  EXPECT_EQ(udpm_fragments_per_datagram(576), 119);  // 552 B each: 118 hold 65 136
  EXPECT_EQ(udpm_fragments_per_datagram(65535), 1);  // 65 515 + 20 fits whole
  EXPECT_EQ(udpm_fragments_per_datagram(65536), 1);  // lo
}

TEST(UdpmRoute, AdviceOnlyForAGroupKeptOnThisHostWhoseDatagramsAreFragmented) {
  using trajroi::daemon::udpm_route_advice;
  trajroi::daemon::LcmGroup group{"239.255.76.67", 7667, 0, 0};
  const std::string url = "udpm://239.255.76.67:7667?ttl=0";
  const std::string line = udpm_route_advice(url, group, {"eth0", 1500});
  EXPECT_EQ(line.rfind("LCM " + url + ": ", 0), 0U) << line;
  EXPECT_NE(line.find("route goes through eth0 (MTU 1500): each 64 KB datagram of a cloud is cut into 45 IP fragments"),
            std::string::npos)
      << line;
  EXPECT_NE(line.find("ip link set lo multicast on; ip route add 239.255.76.67/32 dev lo; docs/lcm.md)"),
            std::string::npos)
      << line;
  // Already over lo: the small MTU is the route's (its mtu metric) or lo's own, and the remedy
  // says which to mend instead of routing the group over lo again.
  const std::string route_mtu = udpm_route_advice(url, group, {"lo", 1400, true});
  EXPECT_NE(route_mtu.find("goes through lo (MTU 1400): each 64 KB datagram of a cloud is cut into 48 IP fragments"),
            std::string::npos)
      << route_mtu;
  EXPECT_NE(route_mtu.find("the route over lo sets that MTU itself: make it again without mtu (ip route get "
                           "239.255.76.67 shows it"),
            std::string::npos)
      << route_mtu;
  EXPECT_EQ(route_mtu.find("ip route add"), std::string::npos) << route_mtu;
  const std::string link_mtu = udpm_route_advice(url, group, {"lo", 1500, false});
  EXPECT_NE(link_mtu.find("lo's own MTU is that small: give it back its 65536 (ip link set lo mtu 65536; docs/lcm.md)"),
            std::string::npos)
      << link_mtu;
  EXPECT_EQ(udpm_route_advice(url, group, {"lo", 65536}), "");
  EXPECT_EQ(udpm_route_advice(url, group, {"lo", 65535}), "");
  group.ttl = 1;  // meant to leave the host: its route is the network's business
  EXPECT_EQ(udpm_route_advice("udpm://239.255.76.67:7667?ttl=1", group, {"eth0", 1500}), "");
}
