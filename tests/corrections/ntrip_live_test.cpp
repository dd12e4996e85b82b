// The NTRIP client against a real caster: RTKLIB's str2str (Debian rtklib) serving on loopback
// the RTCM3 frames of a real u-blox ZED-F9T stream, which the test writes into str2str's input
// (its TCP server) with garbage and corrupted copies between them. The client must hand on
// exactly the valid frames, in order, none twice; when the caster is stopped and started again
// it says so, reconnects and goes on. Credentials and mountpoints the caster refuses are named
// with the caster's own answer.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "stream_peers.hpp"
#include "test_data.hpp"
#include "trajroi/corrections/ntrip_client.hpp"

namespace trajroi::corrections {
namespace {

using namespace corrections_test;

// Runs the client's loop until `done` or `seconds`.
bool run_until(NtripClient& client, const std::function<bool()>& done, double seconds) {
  const std::int64_t end = now_ns() + static_cast<std::int64_t>(seconds * 1e9);
  while (now_ns() < end) {
    if (done()) return true;
    pollfd p{client.fd(), client.events(), 0};
    const int timeout = std::min(client.timeout_ms(now_ns()), 50);
    if (client.fd() >= 0) {
      (void)::poll(&p, 1, timeout);
    } else {
      ::usleep(static_cast<useconds_t>(timeout) * 1000);
    }
    client.service(client.fd() >= 0 ? p.revents : 0, now_ns());
  }
  return done();
}

struct Received {
  std::vector<Bytes> frames;
  std::vector<std::string> events;
  [[nodiscard]] bool said(const std::string& part) const {
    for (const auto& e : events)
      if (e.find(part) != std::string::npos) return true;
    return false;
  }
};

NtripClient make_client(const std::string& url, Received& r) {
  NtripClientOptions o;
  o.url = parse_ntrip_url(url);
  o.backoff_min_s = 0.5;
  o.backoff_max_s = 2.0;
  o.stall_s = 30.0;
  return NtripClient(
      o, [&r](std::span<const std::uint8_t> f) { r.frames.emplace_back(f.begin(), f.end()); },
      [] {
        return std::string("$GPGGA,120000.00,4807.0380000,N,01131.0000000,E,1,08,0.9,545.400,M,46.900,M,,*55\r\n");
      },
      [&r](const std::string& e) { r.events.push_back(e); });
}

TEST(NtripClientLive, HandsOnExactlyTheValidFramesAcrossACasterRestart) {
  REQUIRE_STREAM_PEERS();
  TRAJROI_REQUIRE_DATA(path, "ublox/gpsd/ublox-zed-f9t-rtcm3.log");
  const std::vector<Bytes> frames = log_frames(test::read_file(path));
  ASSERT_EQ(frames.size(), 182U);
  const std::uint16_t input = free_port(), port = free_port();
  Caster caster(input, port);
  Received r;
  NtripClient client = make_client("ntrip://rover:s3cret@127.0.0.1:" + std::to_string(port) + "/F9T", r);
  ASSERT_TRUE(run_until(
      client, [&] { return client.streaming(); }, 10))
      << client.state();
  EXPECT_TRUE(r.said("connected to ntrip://rover:***@127.0.0.1:" + std::to_string(port) + "/F9T"));

  std::size_t corrupted = 0;
  caster.write(with_noise(frames, 0, 90, corrupted));
  ASSERT_TRUE(run_until(
      client, [&] { return r.frames.size() >= 90; }, 20))
      << r.frames.size() << " frames";

  // The caster goes away and comes back.
  caster.close_inputs();
  caster.stop();
  ASSERT_TRUE(run_until(
      client, [&] { return r.said("the caster closed the connection"); }, 10))
      << client.state();
  caster.start();
  ASSERT_TRUE(run_until(
      client, [&] { return client.streaming(); }, 15))
      << client.state();
  caster.write(with_noise(frames, 90, frames.size(), corrupted));
  ASSERT_TRUE(run_until(
      client, [&] { return r.frames.size() >= frames.size(); }, 20))
      << r.frames.size();
  run_until(
      client, [] { return false; }, 0.5);  // nothing more may come

  ASSERT_EQ(r.frames.size(), frames.size()) << "each valid frame once";
  for (std::size_t i = 0; i < frames.size(); ++i)
    ASSERT_EQ(r.frames[i], frames[i]) << "frame " << i;
  const CorrectionCounters& c = client.counters();
  EXPECT_EQ(c.frames, frames.size());
  EXPECT_GE(c.crc_errors, corrupted) << "every corrupted copy failed its CRC";
  EXPECT_EQ(c.connects, 2U);
  EXPECT_EQ(c.disconnects, 1U);
  EXPECT_EQ(c.by_message.at(1077), 26U);
  EXPECT_EQ(c.by_message.at(1230), 26U);
  EXPECT_GE(c.gga_sent, 2U) << "the rover's GGA with each request";
}

TEST(NtripClientLive, RefusalsAreNamedWithTheCastersAnswer) {
  REQUIRE_STREAM_PEERS();
  const std::uint16_t input = free_port(), port = free_port();
  Caster caster(input, port);
  Received wrong_password;
  NtripClient a =
      make_client("ntrip://rover:wrong@127.0.0.1:" + std::to_string(port) + "/F9T?version=1", wrong_password);
  // (While str2str starts, the first attempts may find no one listening: "cannot connect".)
  EXPECT_TRUE(run_until(
      a, [&] { return wrong_password.said("refused by the caster: HTTP/1.0 401 Unauthorized"); }, 10))
      << a.state();
  EXPECT_FALSE(a.streaming());

  Received wrong_mount;
  NtripClient b = make_client("ntrip://rover:s3cret@127.0.0.1:" + std::to_string(port) + "/NOPE", wrong_mount);
  EXPECT_TRUE(run_until(
      b, [&] { return wrong_mount.said("mountpoint NOPE is not on the caster; it has: F9T"); }, 10))
      << b.state();
  EXPECT_GE(b.counters().refusals, 1U);
  // It keeps trying, backing off.
  EXPECT_NE(b.state().find("to reconnect to ntrip://rover:***@127.0.0.1:"), std::string::npos) << b.state();
  EXPECT_EQ(b.counters().connects, 0U);
}

}  // namespace
}  // namespace trajroi::corrections
