// LCM's UDP multicast wire format: trajroid's datagrams against liblcm's own, byte for byte
// (liblcm publishes, a plain socket on a private port of the group captures), and messages
// rebuilt from datagrams however they arrive.
#include "trajroi/transport/lcm_udpm.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace udpm = trajroi::transport::udpm;

namespace {

constexpr const char* kGroup = "239.255.76.67";

std::vector<std::uint8_t> bytes_of(std::size_t n, std::uint32_t seed) {
  std::vector<std::uint8_t> v(n);
  std::mt19937 random(seed);
  for (auto& b : v)
    b = static_cast<std::uint8_t>(random());
  return v;
}

// One datagram as it goes on the wire: header, channel, payload.
std::vector<std::uint8_t> wire(const udpm::Datagram& d) {
  std::vector<std::uint8_t> w(d.header.begin(), d.header.begin() + static_cast<std::ptrdiff_t>(d.header_bytes));
  w.insert(w.end(), d.channel.begin(), d.channel.end());
  w.insert(w.end(), d.payload.begin(), d.payload.end());
  return w;
}

// A socket in the group on a port of its own (ephemeral: no other test or LCM client uses it).
struct Capture {
  int fd = -1;
  int port = 0;
  Capture() {
    fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_ANY);
    socklen_t length = sizeof a;
    const int buffer = 4 << 20;
    ip_mreq m{};
    inet_pton(AF_INET, kGroup, &m.imr_multiaddr);
    if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        getsockname(fd, reinterpret_cast<sockaddr*>(&a), &length) != 0 ||
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer) != 0 ||
        setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &m, sizeof m) != 0) {
      ADD_FAILURE() << "cannot open a multicast socket on loopback: " << std::strerror(errno);
    }
    port = ntohs(a.sin_port);
  }
  ~Capture() { close(fd); }
  std::vector<std::uint8_t> next() const {
    pollfd p{fd, POLLIN, 0};
    std::vector<std::uint8_t> d(70000);
    if (poll(&p, 1, 2000) != 1) return {};
    const ssize_t n = recv(fd, d.data(), d.size(), 0);
    d.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return d;
  }
};

}  // namespace

TEST(LcmUdpm, DatagramsAreLiblcmsByteForByte) {
  Capture capture;
  lcm::LCM lcm("udpm://" + std::string(kGroup) + ":" + std::to_string(capture.port) + "?ttl=0");
  ASSERT_TRUE(lcm.good());
  const std::string channel = "TRAJROI_POINTS";
  // Short, the longest short, the shortest fragmented, exactly two fragments, several.
  const std::size_t room = udpm::kShortMessageMax - channel.size() - 1;
  const std::vector<std::size_t> sizes{0, 10, room, room + 1, 2 * udpm::kFragmentMax - channel.size() - 1, 230000};
  std::vector<udpm::Datagram> datagrams;
  for (std::uint32_t seqno = 0; seqno < sizes.size(); ++seqno) {
    const std::vector<std::uint8_t> payload = bytes_of(sizes[seqno], seqno);
    ASSERT_EQ(lcm.publish(channel, payload.data(), static_cast<unsigned>(payload.size())), 0);
    ASSERT_TRUE(udpm::split_message(channel, payload, seqno, datagrams));
    const std::size_t expected =
        sizes[seqno] + channel.size() + 1 <= udpm::kShortMessageMax
            ? 1
            : (sizes[seqno] + channel.size() + 1 + udpm::kFragmentMax - 1) / udpm::kFragmentMax;
    EXPECT_EQ(datagrams.size(), expected) << sizes[seqno] << " B";
    for (const udpm::Datagram& d : datagrams) {
      const std::vector<std::uint8_t> theirs = capture.next();
      ASSERT_FALSE(theirs.empty()) << "liblcm's datagram of a " << sizes[seqno] << " B message did not arrive";
      EXPECT_LE(theirs.size(), udpm::kMaxDatagramBytes);
      EXPECT_TRUE(theirs == wire(d)) << sizes[seqno] << " B message, datagram of " << theirs.size() << " B";
    }
  }
}

TEST(LcmUdpm, RefusesWhatLcmCannotCarry) {
  std::vector<udpm::Datagram> d;
  const std::vector<std::uint8_t> payload(10);
  EXPECT_FALSE(udpm::split_message("", payload, 0, d));
  EXPECT_FALSE(udpm::split_message(std::string(64, 'C'), payload, 0, d));
  EXPECT_TRUE(udpm::split_message(std::string(63, 'C'), payload, 0, d));
  EXPECT_EQ(d.size(), 1u);
}

TEST(LcmUdpm, MessagesAreRebuiltInAnyOrderAfterTheirFirstFragment) {
  const std::string channel = "TRAJROI_TRAJECTORY";
  udpm::Reassembler r({channel});
  std::vector<udpm::Datagram> datagrams;
  for (const std::size_t size : {std::size_t{0}, std::size_t{1000}, std::size_t{300000}}) {
    const std::vector<std::uint8_t> payload = bytes_of(size, static_cast<std::uint32_t>(size));
    ASSERT_TRUE(udpm::split_message(channel, payload, 7, datagrams));
    std::vector<std::vector<std::uint8_t>> wires;
    for (const auto& d : datagrams)
      wires.push_back(wire(d));
    // The first first, the rest reversed, one of them twice.
    std::reverse(wires.begin() + 1, wires.end());
    if (wires.size() > 2) wires.insert(wires.begin() + 2, wires[1]);
    udpm::Reassembler::Message m;
    for (std::size_t i = 0; i + 1 < wires.size(); ++i)
      ASSERT_EQ(r.accept(42, wires[i], m), udpm::Reassembler::Verdict::kPending) << size << " B, datagram " << i;
    ASSERT_EQ(r.accept(42, wires.back(), m), udpm::Reassembler::Verdict::kMessage) << size << " B";
    EXPECT_EQ(m.channel, channel);
    EXPECT_TRUE(std::equal(m.payload.begin(), m.payload.end(), payload.begin(), payload.end())) << size << " B";
  }
  EXPECT_EQ(r.counters().messages, 3u);
  EXPECT_EQ(r.counters().malformed, 0u);
}

TEST(LcmUdpm, OtherChannelsAndLostStartsAreSkippedAndAbandonedMessagesCounted) {
  udpm::Reassembler r({"WANTED"});
  std::vector<udpm::Datagram> datagrams;
  const std::vector<std::uint8_t> big = bytes_of(200000, 1);
  udpm::Reassembler::Message m;
  const std::string other = "TRAJROI_POINTS";
  ASSERT_TRUE(udpm::split_message(other, big, 1, datagrams));
  for (const auto& d : datagrams)
    EXPECT_EQ(r.accept(1, wire(d), m), udpm::Reassembler::Verdict::kOtherChannel);
  const std::string wanted = "WANTED";
  ASSERT_TRUE(udpm::split_message(wanted, big, 2, datagrams));
  // Its first fragment lost: the rest cannot be placed.
  for (std::size_t i = 1; i < datagrams.size(); ++i)
    EXPECT_EQ(r.accept(1, wire(datagrams[i]), m), udpm::Reassembler::Verdict::kOtherChannel);
  // Begun, then the sender moves on to its next message: the first is abandoned; the second
  // completes. Another sender's fragments in between do not mix in.
  EXPECT_EQ(r.accept(1, wire(datagrams[0]), m), udpm::Reassembler::Verdict::kPending);
  const std::vector<std::uint8_t> second = bytes_of(150000, 2);
  std::vector<udpm::Datagram> next;
  ASSERT_TRUE(udpm::split_message(wanted, second, 3, next));
  std::vector<udpm::Datagram> interleaved;
  ASSERT_TRUE(udpm::split_message(wanted, big, 3, interleaved));
  EXPECT_EQ(r.accept(2, wire(interleaved[0]), m), udpm::Reassembler::Verdict::kPending);
  for (std::size_t i = 0; i + 1 < next.size(); ++i)
    EXPECT_EQ(r.accept(1, wire(next[i]), m), udpm::Reassembler::Verdict::kPending);
  EXPECT_EQ(r.counters().abandoned, 1u);
  ASSERT_EQ(r.accept(1, wire(next.back()), m), udpm::Reassembler::Verdict::kMessage);
  EXPECT_TRUE(std::equal(m.payload.begin(), m.payload.end(), second.begin(), second.end()));
  for (std::size_t i = 1; i < interleaved.size(); ++i)
    (void)r.accept(2, wire(interleaved[i]), m);
  EXPECT_TRUE(std::equal(m.payload.begin(), m.payload.end(), big.begin(), big.end()));
  EXPECT_EQ(r.counters().messages, 2u);
  EXPECT_EQ(r.counters().malformed, 0u);
}

TEST(LcmUdpm, MalformedDatagramsAreCountedNotDelivered) {
  udpm::Reassembler r({"WANTED"}, 100000);
  udpm::Reassembler::Message m;
  const auto verdict = [&](std::vector<std::uint8_t> d) { return r.accept(9, d, m); };
  const auto header = [](std::uint32_t magic, std::uint32_t size, std::uint32_t offset, std::uint16_t number,
                         std::uint16_t count) {
    std::vector<std::uint8_t> h(20);
    const auto u32 = [&](std::size_t at, std::uint32_t v) {
      for (int i = 0; i < 4; ++i)
        h[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (24 - 8 * i));
    };
    u32(0, magic);
    u32(4, 5);
    u32(8, size);
    u32(12, offset);
    h[16] = static_cast<std::uint8_t>(number >> 8);
    h[17] = static_cast<std::uint8_t>(number);
    h[18] = static_cast<std::uint8_t>(count >> 8);
    h[19] = static_cast<std::uint8_t>(count);
    return h;
  };
  const auto with_channel = [](std::vector<std::uint8_t> d, const std::string& channel, std::size_t payload) {
    d.insert(d.end(), channel.begin(), channel.end());
    d.push_back(0);
    d.resize(d.size() + payload, 0xAB);
    return d;
  };
  using V = udpm::Reassembler::Verdict;
  EXPECT_EQ(verdict({}), V::kMalformed);
  EXPECT_EQ(verdict({'L', 'C', '0', '2', 0, 0, 0}), V::kMalformed);                    // short header
  EXPECT_EQ(verdict({'X', 'C', '0', '2', 0, 0, 0, 0, 'W'}), V::kMalformed);            // not LCM
  EXPECT_EQ(verdict({'L', 'C', '0', '2', 0, 0, 0, 0, 'W', 'A', 'N'}), V::kMalformed);  // channel unterminated
  EXPECT_EQ(verdict({'L', 'C', '0', '2', 0, 0, 0, 0, 0, 1, 2}), V::kMalformed);        // empty channel
  EXPECT_EQ(verdict(with_channel({'L', 'C', '0', '2', 0, 0, 0, 0}, std::string(64, 'W'), 1)), V::kMalformed);
  EXPECT_EQ(verdict(header(udpm::kMagicLong, 10, 0, 0, 1)), V::kMalformed);  // first fragment without channel
  EXPECT_EQ(verdict(with_channel(header(udpm::kMagicLong, 10, 0, 0, 0), "WANTED", 10)), V::kMalformed);  // 0 fragments
  EXPECT_EQ(verdict(with_channel(header(udpm::kMagicLong, 10, 0, 2, 2), "WANTED", 10)),
            V::kMalformed);  // number ≥ count
  EXPECT_EQ(verdict(with_channel(header(udpm::kMagicLong, 10, 4, 0, 2), "WANTED", 5)), V::kMalformed);   // first at 4
  EXPECT_EQ(verdict(with_channel(header(udpm::kMagicLong, 10, 0, 0, 2), "WANTED", 11)), V::kMalformed);  // over size
  EXPECT_EQ(verdict(with_channel(header(udpm::kMagicLong, 200000, 0, 0, 4), "WANTED", 10)), V::kMalformed);  // too big
  // A consistent first fragment, then a second one past the end, one that changes the count.
  EXPECT_EQ(verdict(with_channel(header(udpm::kMagicLong, 10, 0, 0, 2), "WANTED", 6)), V::kPending);
  std::vector<std::uint8_t> past = header(udpm::kMagicLong, 10, 8, 1, 2);
  past.resize(past.size() + 4, 1);
  EXPECT_EQ(verdict(past), V::kMalformed);
  std::vector<std::uint8_t> recount = header(udpm::kMagicLong, 10, 6, 1, 3);
  recount.resize(recount.size() + 4, 1);
  EXPECT_EQ(verdict(recount), V::kMalformed);
  std::vector<std::uint8_t> fits = header(udpm::kMagicLong, 10, 6, 1, 2);
  fits.resize(fits.size() + 4, 1);
  ASSERT_EQ(verdict(fits), V::kMessage);
  EXPECT_EQ(m.payload.size(), 10u);
  EXPECT_EQ(r.counters().messages, 1u);
  EXPECT_EQ(r.counters().malformed, 14u);
}

TEST(LcmUdpm, PartialMessagesAreBoundedInNumberAndBytes) {
  udpm::Reassembler r({"WANTED"});
  udpm::Reassembler::Message m;
  std::vector<udpm::Datagram> datagrams;
  const std::string channel = "WANTED";
  // 17 senders each begin a message: the first one begun goes.
  const std::vector<std::uint8_t> payload = bytes_of(100000, 5);
  ASSERT_TRUE(udpm::split_message(channel, payload, 1, datagrams));
  for (std::uint64_t sender = 1; sender <= 17; ++sender)
    ASSERT_EQ(r.accept(sender, wire(datagrams[0]), m), udpm::Reassembler::Verdict::kPending);
  EXPECT_EQ(r.counters().abandoned, 1u);
  EXPECT_EQ(r.accept(1, wire(datagrams[1]), m), udpm::Reassembler::Verdict::kOtherChannel);  // its start is gone
  // A 10 MB message takes a 17th slot (one more small one goes); a second does not fit in
  // 16 MiB beside it: the least recently fed go until it does, the small ones, then the first.
  const std::vector<std::uint8_t> big = bytes_of(10u << 20, 6);
  ASSERT_TRUE(udpm::split_message(channel, big, 2, datagrams));
  ASSERT_EQ(r.accept(100, wire(datagrams[0]), m), udpm::Reassembler::Verdict::kPending);
  ASSERT_EQ(r.accept(101, wire(datagrams[0]), m), udpm::Reassembler::Verdict::kPending);
  EXPECT_EQ(r.counters().abandoned, 18u);  // 1 + 1 + the other 15 small ones + the first big one
  for (std::size_t i = 1; i < datagrams.size(); ++i)
    (void)r.accept(101, wire(datagrams[i]), m);
  EXPECT_EQ(r.counters().messages, 1u);
  EXPECT_TRUE(std::equal(m.payload.begin(), m.payload.end(), big.begin(), big.end()));
}
