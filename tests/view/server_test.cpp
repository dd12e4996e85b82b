// The view's server on real sockets (loopback): pages over HTTP, the WebSocket upgrade, and
// the newest-frame-wins rule: a client that never reads does not hold up one that does (it
// gets the newest frame), a client that goes away in the middle of a frame is closed alone,
// and the per-client rate cap spaces the sweeps.
#include "trajroi/view/server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "trajroi/view/websocket.hpp"

namespace trajroi::view {
namespace {

using Clock = std::chrono::steady_clock;

int connect_to(std::uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  return fd;
}

bool read_exactly(int fd, std::uint8_t* out, std::size_t n) {
  for (std::size_t got = 0; got < n;) {
    const ssize_t r = ::recv(fd, out + got, n - got, 0);
    if (r <= 0) return false;
    got += static_cast<std::size_t>(r);
  }
  return true;
}

std::string read_head(int fd) {
  std::string head;
  char c = 0;
  while (head.find("\r\n\r\n") == std::string::npos && ::recv(fd, &c, 1, 0) == 1)
    head += c;
  return head;
}

// A WebSocket page: the upgrade, then frames.
struct Page {
  int fd = -1;
  explicit Page(std::uint16_t port) : fd(connect_to(port)) {
    const std::string request =
        "GET /ws HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
    (void)::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  }
  ~Page() {
    if (fd >= 0) ::close(fd);
  }
  // One frame's payload (empty on a timeout or a close).
  std::vector<std::uint8_t> frame() {
    std::uint8_t h[2];
    if (!read_exactly(fd, h, 2)) return {};
    std::uint64_t n = h[1] & 0x7F;
    if (n == 126 || n == 127) {
      std::uint8_t ext[8];
      const std::size_t k = n == 126 ? 2 : 8;
      if (!read_exactly(fd, ext, k)) return {};
      n = 0;
      for (std::size_t i = 0; i < k; ++i)
        n = n << 8 | ext[i];
    }
    std::vector<std::uint8_t> payload(static_cast<std::size_t>(n));
    if (!read_exactly(fd, payload.data(), payload.size())) return {};
    return payload;
  }
};

// A frame of `size` bytes whose JSON header says `i`.
std::shared_ptr<const std::vector<std::uint8_t>> numbered(int i, std::size_t size) {
  std::vector<std::uint8_t> body(size, static_cast<std::uint8_t>(i));
  const std::span<const std::uint8_t> arrays[] = {body};
  return std::make_shared<const std::vector<std::uint8_t>>(
      encode_frame(FrameKind::kSweep, "{\"i\":" + std::to_string(i) + "}", arrays));
}

int number_of(const std::vector<std::uint8_t>& frame) {
  const std::string head(frame.begin() + 12, frame.begin() + 24);
  return std::atoi(head.c_str() + head.find(':') + 1);
}

std::shared_ptr<const std::vector<std::uint8_t>> text(std::string s) {
  return std::make_shared<const std::vector<std::uint8_t>>(s.begin(), s.end());
}

TEST(ViewServer, ServesThePageAndRefusesWhatItDoesNotKnow) {
  ViewServer server({"127.0.0.1", 0, 10.0}, {{"/", "text/html", text("<html>hi</html>")}});
  std::atomic<bool> done{false};
  std::thread loop([&] {
    while (!done)
      (void)server.poll(-1, 20);
  });
  const auto get = [&](const std::string& request) {
    const int fd = connect_to(server.port());
    (void)::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
    std::string all;
    char buf[4096];
    ssize_t n = 0;
    while ((n = ::recv(fd, buf, sizeof buf, 0)) > 0)
      all.append(buf, static_cast<std::size_t>(n));
    ::close(fd);
    return all;
  };
  const std::string page = get("GET / HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(page.substr(0, 15), "HTTP/1.1 200 OK");
  EXPECT_NE(page.find("Content-Length: 15\r\n"), std::string::npos);
  EXPECT_EQ(page.substr(page.size() - 15), "<html>hi</html>");
  EXPECT_EQ(get("GET /nothing HTTP/1.1\r\n\r\n").substr(0, 12), "HTTP/1.1 404");
  EXPECT_EQ(get("GARBAGE\r\n\r\n").substr(0, 12), "HTTP/1.1 400");
  const std::string refused = get("GET /ws HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_NE(refused.find("no Upgrade: websocket"), std::string::npos);
  done = true;
  loop.join();
  EXPECT_EQ(server.counters().bad_requests, 2U);
}

TEST(ViewServer, AnAddressInUseIsNamed) {
  ViewServer first({"127.0.0.1", 0, 10.0}, {});
  try {
    ViewServer second({"127.0.0.1", first.port(), 10.0}, {});
    FAIL() << "bound twice";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(first.port()) + ": Address already in use"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ViewServer({"robot.local", 0, 10.0}, {}), std::runtime_error);
}

TEST(ViewServer, ASlowPageSkipsFramesAndHoldsUpNoOther) {
  ViewServer server({"127.0.0.1", 0, 1000.0}, {});
  Page fast(server.port()), slow(server.port()), leaving(server.port());
  // The three upgrades answered.
  const auto until = Clock::now() + std::chrono::seconds(5);
  while (server.websocket_clients() < 3 && Clock::now() < until)
    (void)server.poll(-1, 10);
  ASSERT_EQ(server.websocket_clients(), 3U);
  ASSERT_NE(read_head(fast.fd).find("101 Switching Protocols"), std::string::npos);
  ASSERT_NE(read_head(leaving.fd).find("101"), std::string::npos);
  // The leaving page reads the start of the first frame, then goes.
  std::atomic<bool> done{false};
  std::atomic<int> last_seen{-1}, frames_seen{0};
  std::thread reader([&] {
    while (!done) {
      const std::vector<std::uint8_t> f = fast.frame();
      if (f.empty()) continue;
      last_seen = number_of(f);
      ++frames_seen;
    }
  });
  constexpr int kFrames = 40;
  constexpr std::size_t kSize = 1 << 20;  // 1 MiB: the socket buffers hold a few
  for (int i = 0; i < kFrames; ++i) {
    server.publish(FrameKind::kSweep, numbered(i, kSize));
    const auto t0 = Clock::now();
    (void)server.poll(-1, 5);
    // The server never waits for a client: one poll round is short however full the slow
    // page's socket is.
    EXPECT_LT(Clock::now() - t0, std::chrono::milliseconds(500));
    if (i == 1) {
      std::uint8_t part[1000];
      (void)read_exactly(leaving.fd, part, sizeof part);
      ::close(leaving.fd);
      leaving.fd = -1;
    }
  }
  const auto end = Clock::now() + std::chrono::seconds(10);
  while (last_seen != kFrames - 1 && Clock::now() < end)
    (void)server.poll(-1, 10);
  done = true;
  ::shutdown(fast.fd, SHUT_RD);
  reader.join();
  EXPECT_EQ(last_seen, kFrames - 1) << "the reading page got the newest frame";
  EXPECT_GT(server.counters().frames_replaced, 0U) << "the slow page's queued frames were replaced";
  EXPECT_EQ(server.websocket_clients(), 2U) << "the page that left mid-frame was closed, alone";
  EXPECT_EQ(server.counters().disconnects, 1U);
  std::printf("fast page: %d of %d frames; frames replaced for slow pages: %llu\n", frames_seen.load(), kFrames,
              static_cast<unsigned long long>(server.counters().frames_replaced));
}

TEST(ViewServer, TheRateCapSpacesSweepsPerPage) {
  ViewServer server({"127.0.0.1", 0, 5.0}, {});
  Page page(server.port());
  while (server.websocket_clients() < 1)
    (void)server.poll(-1, 10);
  ASSERT_NE(read_head(page.fd).find("101"), std::string::npos);
  std::atomic<bool> done{false};
  std::vector<Clock::time_point> arrivals;
  std::thread reader([&] {
    while (!done) {
      if (!page.frame().empty()) arrivals.push_back(Clock::now());
    }
  });
  const auto start = Clock::now();
  for (int i = 0; Clock::now() - start < std::chrono::milliseconds(1500); ++i) {
    server.publish(FrameKind::kSweep, numbered(i, 100));
    (void)server.poll(-1, 2);
  }
  done = true;
  ::shutdown(page.fd, SHUT_RD);
  reader.join();
  // 5 per second at most: 1.5 s gives 8 (the first at once) whatever the machine's load.
  EXPECT_GE(arrivals.size(), 5U);
  EXPECT_LE(arrivals.size(), 8U);
}

}  // namespace
}  // namespace trajroi::view
