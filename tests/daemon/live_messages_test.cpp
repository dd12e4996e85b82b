// Every line trajroid says is true and tells the user what to do: each case driven live, on
// real bytes where the data set has them (the VLP-16 capture over UDP to 127.0.0.1, u-blox and
// VN-100 logs and the sentences and frames cut from them through pseudo-terminals, a
// localization published by the project's own Python module over LCM on loopback), asserting
// the log line, that it came within 5 s, and the status message's words.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cmath>
#include <random>

#include "real_rig.hpp"
#include "test_data.hpp"
#include "trajroi/framing/protocol_sniffer.hpp"

namespace {

using namespace daemon_test;

// The newest status message heard, or an empty one.
trajroi::status_t last_status(Listener& listener) {
  std::lock_guard<std::mutex> lock(listener.mutex);
  return listener.statuses.empty() ? trajroi::status_t{} : listener.statuses.back();
}

// Waits until the newest status message's state contains `text`.
bool state_says(Listener& listener, const std::string& text, std::chrono::milliseconds timeout) {
  return listener.wait_for(
      [&] { return !listener.statuses.empty() && listener.statuses.back().state.find(text) != std::string::npos; },
      timeout);
}

// Sends `count` datagrams of random sizes (1 … 1500 bytes) and bytes from 127.0.0.1 to `port`.
void send_garbage(int port, int count) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::mt19937 random(42);
  std::vector<std::uint8_t> bytes(1500);
  for (int i = 0; i < count; ++i) {
    const std::size_t n = 1 + random() % 1500;
    for (std::size_t k = 0; k < n; ++k)
      bytes[k] = static_cast<std::uint8_t>(random());
    (void)sendto(fd, bytes.data(), n, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
    std::this_thread::sleep_for(milliseconds(2));
  }
  close(fd);
}

// The NMEA sentences of a u-blox log ('$' to its line feed, printable), without its UBX frames.
std::string nmea_of(const std::string& log) {
  std::string out;
  for (std::size_t at = log.find('$'); at != std::string::npos; at = log.find('$', at + 1)) {
    const std::size_t end = log.find('\n', at);
    if (end == std::string::npos || end - at > 100) continue;
    const std::string line = log.substr(at, end - at + 1);
    bool text = true;
    for (const char c : line)
      text = text && (c == '\r' || c == '\n' || (c >= 0x20 && c < 0x7F));
    if (text && line.find('*') != std::string::npos) out += line;
  }
  return out;
}

// The RTCM3 frames of a u-blox log (0xD3, length, CRC-24Q correct), without anything else.
std::string rtcm3_of(const std::string& log) {
  std::string out;
  for (std::size_t at = 0; at + 6 <= log.size(); ++at) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(log.data() + at);
    if (p[0] != 0xD3 || (p[1] & 0xFC) != 0) continue;
    const std::size_t length = (static_cast<std::size_t>(p[1] & 3) << 8) | p[2];
    if (length == 0 || at + 6 + length > log.size()) continue;
    const std::uint32_t crc =
        (std::uint32_t{p[3 + length]} << 16) | (std::uint32_t{p[4 + length]} << 8) | p[5 + length];
    if (trajroi::framing::crc24q({p, 3 + length}) != crc) continue;
    out.append(log, at, 6 + length);
    at += 5 + length;
  }
  return out;
}

// `bytes` written into `rig`'s device `link` by `trajroi feed` (one chunk per 0xFA byte at 20 per
// second: text without 0xFA goes at once), the device kept for `linger` s.
std::vector<std::string> serial_feed(const fs::path& file, const fs::path& link, const std::string& linger) {
  return {"feed", "--vn100", file.string(), "--imu-link", link.string(), "--vn100-rate", "20", "--linger", linger};
}

// ---- the LiDAR port ------------------------------------------------------------------------

TEST(LiveMessages, GarbageOnTheLidarPortIsNamedWithSizesAndSendersAndNotBlamedOnTheGnss) {
  const Rig rig("garbage", "gnss_imu", 12);  // no GNSS nor IMU device: their state is their own
  Listener listener(rig.prefix);
  ASSERT_TRUE(listener.good());
  Child daemon(rig.daemon_args(), rig.daemon_log);
  ASSERT_TRUE(wait_until_running(rig.daemon_log)) << rig.logs();
  const auto start = std::chrono::steady_clock::now();
  std::thread sender([&] { send_garbage(rig.data_port, 2000); });
  EXPECT_LOGGED_WITHIN_5S(rig, "none a VLP-16 data packet (", start);
  sender.join();
  const std::string log = slurp(rig.daemon_log);
  const auto at = log.find("none a VLP-16 data packet (");
  ASSERT_NE(at, std::string::npos);
  const std::string line = log.substr(at, log.find('\n', at) - at);
  EXPECT_NE(line.find("a VLP-16 sends 1206; from 127.0.0.1:"), std::string::npos) << line;
  EXPECT_NE(line.find("another device sends to this port (lidar.data_port)"), std::string::npos) << line;
  EXPECT_EQ(log.find("lidar: no datagrams"), std::string::npos) << "they come: not silent\n" << log;
  ASSERT_TRUE(state_says(listener, "LiDAR: no VLP-16 packets on UDP port " + std::to_string(rig.data_port), seconds(3)))
      << last_status(listener).state;
  const trajroi::status_t s = last_status(listener);
  EXPECT_EQ(s.state.find("no valid pose"), std::string::npos) << s.state;
  EXPECT_NE(s.state.find("GNSS: cannot open " + rig.gnss_link.string() + "; waiting for it"), std::string::npos)
      << s.state;
  EXPECT_GE(counter(s, "lidar.not_vlp16_datagrams"), 1000);
  rig.stop(daemon);
}

// The sensor's packets and other datagrams on the same port: said once a minute, with the counts.
TEST(LiveMessages, OtherDatagramsAmidTheSensorsPacketsAreSummarisedOnceAMinute) {
  const fs::path& corridor = corridor_run();  // simulated before the clock starts
  const Rig rig("mixed", "fixed", 11);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  // The corridor's 29 s of VLP-16 data at 0.45 × real time: 64 s of packets.
  Child lidar(TRAJROI_CLI, rig.pcap_feed(corridor / "lidar.pcap", "0.5", {"--rate", "0.45"}), rig.feed_log);
  // The other sender starts once the sensor's sweeps are published (else it would be alone).
  ASSERT_GE(seconds_until_logged(rig.daemon_log, "status: publishing", start, seconds(10)), 0.0) << rig.logs();
  std::atomic<bool> stop{false};
  std::thread sender([&] {
    while (!stop) {
      send_garbage(rig.data_port, 5);
      std::this_thread::sleep_for(milliseconds(200));
    }
  });
  const double at = seconds_until_logged(rig.daemon_log, "were not VLP-16 data packets, beside ", start, seconds(70));
  stop = true;
  sender.join();
  EXPECT_GE(at, 55.0) << rig.logs();
  EXPECT_LE(at, 66.0) << rig.logs();
  const std::string log = slurp(rig.daemon_log);
  EXPECT_NE(log.find("from 127.0.0.1:"), std::string::npos) << log;
  EXPECT_EQ(log.find("none a VLP-16 data packet"), std::string::npos) << "the sensor's packets came too\n" << log;
  rig.stop(daemon);
}

// ---- what a serial port carries --------------------------------------------------------------

TEST(LiveMessages, NmeaOnTheReceiverPortIsNamedWithItsRemedy) {
  TRAJROI_REQUIRE_DATA(log, "ublox/gpsd/ublox-zed-f9r.log");
  const Rig rig("nmea", "gnss", 13);
  const fs::path text = rig.dir / "nmea.txt";
  std::ofstream(text, std::ios::binary) << nmea_of(trajroi::test::read_file(log));
  Listener listener(rig.prefix);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, serial_feed(text, rig.gnss_link, "8"), rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(rig,
                          "gnss: NMEA text, no UBX: 871 NMEA sentences and no UBX frame in 3 s from " +
                              rig.gnss_link.string() +
                              ": enable UBX output (UBX-NAV-PVT) on this port, or set gnss.configure: true",
                          start);
  EXPECT_EQ(slurp(rig.daemon_log).find("wrong baud rate"), std::string::npos) << rig.logs();
  EXPECT_TRUE(state_says(listener, "GNSS: NMEA text, no UBX, from " + rig.gnss_link.string(), seconds(3)))
      << last_status(listener).state;
  EXPECT_EQ(counter(last_status(listener), "gnss.nmea_sentences"), 871);
  rig.stop(daemon);
}

TEST(LiveMessages, Rtcm3OnTheReceiverPortIsNamedAsCorrections) {
  TRAJROI_REQUIRE_DATA(log, "ublox/gpsd/ublox-zed-f9t-rtcm3.log");
  const Rig rig("rtcm", "gnss", 14);
  const fs::path frames = rig.dir / "rtcm3.bin";
  std::ofstream(frames, std::ios::binary) << rtcm3_of(trajroi::test::read_file(log));
  Listener listener(rig.prefix);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, serial_feed(frames, rig.gnss_link, "8"), rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(rig,
                          "RTCM3 frames and no UBX frame in 3 s from " + rig.gnss_link.string() +
                              ": a corrections stream (a base station's or an NTRIP client's output), not the "
                              "receiver's output port",
                          start);
  EXPECT_NE(slurp(rig.daemon_log).find("gnss: RTCM3 corrections, no UBX: "), std::string::npos);
  EXPECT_TRUE(state_says(listener, "GNSS: RTCM3 corrections, no UBX", seconds(3))) << last_status(listener).state;
  rig.stop(daemon);
}

TEST(LiveMessages, VectorNavAsciiOnTheImuPortIsNamedWithItsRemedy) {
  const Rig rig("vnascii", "gnss_imu", 15);
  // What a VN-100 sends in its factory setting: $VNYMR lines at 40 Hz (manual, section 8).
  const fs::path text = rig.dir / "vnymr.txt";
  {
    std::ofstream out(text, std::ios::binary);
    for (int i = 0; i < 200; ++i) {
      char body[160];
      std::snprintf(body, sizeof body,
                    "VNYMR,%+08.3f,+000.023,-001.953,+1.0640,-0.2531,+3.0614,+00.005,+00.344,"
                    "-09.758,-0.001222,-0.000450,-0.001218",
                    6.38 + 0.01 * i);
      unsigned x = 0;
      for (const char* c = body; *c != '\0'; ++c)
        x ^= static_cast<unsigned char>(*c);
      char line[200];
      std::snprintf(line, sizeof line, "$%s*%02X\r\n", body, x);
      out << line;
    }
  }
  Listener listener(rig.prefix);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  Child feeder(TRAJROI_CLI, serial_feed(text, rig.imu_link, "8"), rig.feed_log);
  EXPECT_LOGGED_WITHIN_5S(rig,
                          "imu: VN-100 ASCII output, no binary: 200 $VN sentences and no binary frame in 3 s from " +
                              rig.imu_link.string() +
                              ": enable binary output (register 75) on this port, or set imu.configure: true",
                          start);
  EXPECT_TRUE(state_says(listener, "IMU: VN-100 ASCII output, no binary, from " + rig.imu_link.string(), seconds(3)))
      << last_status(listener).state;
  rig.stop(daemon);
}

// A device that is not there is said once, with errno, waited for, and not also called silent.
TEST(LiveMessages, AMissingDeviceIsWaitedForNotAlsoCalledSilent) {
  const Rig rig("absent", "gnss", 0);
  Listener listener(rig.prefix);
  const auto start = std::chrono::steady_clock::now();
  Child daemon(rig.daemon_args(), rig.daemon_log);
  EXPECT_LOGGED_WITHIN_5S(rig, "gnss: cannot open " + rig.gnss_link.string() + ": No such file or directory", start);
  EXPECT_TRUE(state_says(listener, "GNSS: cannot open " + rig.gnss_link.string() + "; waiting for it", seconds(6)))
      << last_status(listener).state;
  std::this_thread::sleep_for(seconds(2));  // past the 3 s in which "no bytes" would come
  EXPECT_EQ(slurp(rig.daemon_log).find("gnss: no bytes"), std::string::npos) << rig.logs();
  rig.stop(daemon);
}

}  // namespace
