// The UDP source on loopback only (127.0.0.1, kernel-chosen ports): datagrams sent here
// come back whole, in order, from the right socket, with a kernel receive time.
#include "trajroi/vlp16/udp_source.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <ctime>
#include <limits>

#include "packet_builder.hpp"

namespace trajroi::vlp16 {
namespace {

class Sender {
 public:
  Sender() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {}
  ~Sender() { ::close(fd_); }
  void send(std::uint16_t port, const std::vector<std::uint8_t>& payload) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::sendto(fd_, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to),
              static_cast<ssize_t>(payload.size()));
  }

 private:
  int fd_;
};

std::int64_t realtime_ns() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

UdpOptions loopback() {
  UdpOptions options;
  options.bind_address = "127.0.0.1";
  options.data_port = 0;
  options.position_port = 0;
  return options;
}

TEST(Vlp16Udp, DataAndPositionDatagramsArriveWholeWithKernelTimes) {
  UdpSource source(loopback());
  ASSERT_NE(source.data_port(), 0);
  ASSERT_NE(source.position_port(), 0);
  EXPECT_GT(source.granted_receive_buffer_bytes(), 0);
  // Linux reports twice the usable size; a warning exactly when that is below the request.
  EXPECT_EQ(source.receive_buffer_warning().empty(),
            source.granted_receive_buffer_bytes() / 2 >= source.requested_receive_buffer_bytes())
      << source.receive_buffer_warning();
  const Sender sender;
  constexpr std::size_t kPackets = 100;
  const std::int64_t before = realtime_ns();
  for (std::size_t i = 0; i < kPackets; ++i) {
    sender.send(source.data_port(), make_packet(static_cast<std::uint16_t>(i * 480 % 36000), 40, ReturnMode::kStrongest,
                                                0x22, static_cast<std::uint32_t>(i)));
  }
  sender.send(source.position_port(), make_position_packet(7, 2, "$GPRMC"));
  std::size_t data = 0, position = 0;
  Datagram datagram;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (data + position < kPackets + 1 && std::chrono::steady_clock::now() < deadline) {
    const PacketSource::Next next = source.next(datagram, std::chrono::milliseconds(100));
    ASSERT_NE(next, PacketSource::Next::kError) << source.error();
    if (next != PacketSource::Next::kDatagram) continue;
    EXPECT_GE(datagram.receive_time_ns, before);
    EXPECT_LE(datagram.receive_time_ns, realtime_ns());
    if (datagram.destination_port == source.data_port()) {
      ASSERT_EQ(datagram.payload.size(), kDataPacketBytes);
      EXPECT_EQ(timestamp_us(datagram.payload), data) << "out of order";
      ++data;
    } else {
      EXPECT_EQ(datagram.destination_port, source.position_port());
      EXPECT_EQ(datagram.payload.size(), kPositionPacketBytes);
      ++position;
    }
  }
  EXPECT_EQ(data, kPackets);
  EXPECT_EQ(position, 1u);
  EXPECT_EQ(source.truncated(), 0u);
  EXPECT_EQ(source.next(datagram, std::chrono::milliseconds(10)), PacketSource::Next::kTimeout);
}

TEST(Vlp16Udp, AnUngrantableBufferIsWarnedAbout) {
  UdpOptions options = loopback();
  options.receive_buffer_bytes = std::numeric_limits<int>::max();  // more than a socket can have
  UdpSource source(options);
  EXPECT_LT(source.granted_receive_buffer_bytes() / 2, options.receive_buffer_bytes);
  EXPECT_NE(source.receive_buffer_warning().find("net.core.rmem_max"), std::string::npos);
}

TEST(Vlp16Udp, OversizedDatagramIsCountedAsTruncated) {
  UdpSource source(loopback());
  const Sender sender;
  sender.send(source.data_port(), std::vector<std::uint8_t>(4000, 1));
  Datagram datagram;
  PacketSource::Next next = PacketSource::Next::kTimeout;
  for (int i = 0; i < 50 && next != PacketSource::Next::kDatagram; ++i) {
    next = source.next(datagram, std::chrono::milliseconds(100));
  }
  ASSERT_EQ(next, PacketSource::Next::kDatagram);
  EXPECT_EQ(source.truncated(), 1u);
  EXPECT_EQ(validate_data_packet(datagram.payload), PacketError::kWrongSize);
}

TEST(Vlp16Udp, BadAddressAndTakenPortAreClearErrors) {
  UdpOptions bad = loopback();
  bad.bind_address = "not-an-address";
  try {
    UdpSource source(bad);
    FAIL() << "bound to a bad address";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not-an-address"), std::string::npos) << e.what();
  }
  // A port already bound without SO_REUSEADDR by another socket.
  const int holder = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(holder, reinterpret_cast<const sockaddr*>(&at), sizeof at), 0);
  socklen_t length = sizeof at;
  ::getsockname(holder, reinterpret_cast<sockaddr*>(&at), &length);
  UdpOptions taken = loopback();
  taken.data_port = ntohs(at.sin_port);
  try {
    UdpSource source(taken);
    FAIL() << "bound to a taken port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(taken.data_port)), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bind"), std::string::npos) << e.what();
  }
  ::close(holder);
}

// The sensor's port is exclusive: a second source on it fails naming the port; with
// share_ports (multicast set-ups) both bind and both receive.
TEST(Vlp16Udp, ThePortIsExclusiveUnlessSharingIsAskedFor) {
  UdpSource first(loopback());
  UdpOptions same = loopback();
  same.data_port = first.data_port();
  same.open_position_socket = false;
  try {
    UdpSource second(same);
    FAIL() << "a second source bound the same port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(same.data_port) +
                                         ": bind: Address already in use (another process receives on this port"),
              std::string::npos)
        << e.what();
  }
  UdpOptions shared = loopback();
  shared.share_ports = true;
  UdpSource a(shared);
  shared.data_port = a.data_port();
  shared.open_position_socket = false;
  EXPECT_NO_THROW(UdpSource b(shared));
}

}  // namespace
}  // namespace trajroi::vlp16
