// trajroid writing RTK corrections into the u-blox port it owns, against real peers: RTKLIB's
// str2str serving the RTCM3 frames of a real ZED-F9T stream (as an NTRIP caster, a TCP server,
// a UDP sender), and rtcm_t messages published with liblcm. The receiver is the other side of
// a pseudo-terminal playing a real ZED-F9R log (an RTK float rover) at its recorded pace and
// acknowledging trajroid's configuration. What the receiver side reads must be exactly the
// valid frames in order (the bit-flipped copies and the noise between them never), besides
// trajroid's own configuration messages; across a caster restart nothing is written twice.

#include <thread>

#include "daemon_fixture.hpp"
#include "pty_receiver.hpp"
#include "stream_peers.hpp"
#include "test_data.hpp"
#include "trajroi/rtcm_t.hpp"

namespace {

using namespace trajroi;
using namespace trajroi::corrections_test;
using daemon_test::Child;
using daemon_test::counter;
using daemon_test::Listener;
namespace fs = std::filesystem;

// A run folder with trajroid's configuration for `url` on channels `prefix`_*: the receiver
// configured, fixed RTK required.
fs::path write_config(const std::string& prefix, const std::string& device, const std::string& url) {
  return write_rover_config(prefix, device,
                            "  configure: true\n  rate_hz: 1\n  corrections: {url: '" + url +
                                "', gga_interval_s: 1, stall_s: 30}\n  max_correction_age_s: 2\n",
                            "  require_rtk: fixed\n  max_extrapolation_s: 1.5\n");
}

bool wait_frames(Receiver& rx, std::size_t n, double seconds = 15.0) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<int>(seconds * 1000));
  while (std::chrono::steady_clock::now() < until) {
    if (rx.split().rtcm.size() >= n) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// What the receiver read: exactly `frames` in order, besides the configuration (CFG-VALSET
// only), nothing else.
void expect_exactly(Receiver& rx, const std::vector<Bytes>& frames) {
  const Receiver::Split s = rx.split();
  ASSERT_EQ(s.rtcm.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(s.rtcm[i], frames[i]) << "frame " << i;
  for (const auto& [c, id] : s.ubx)
    EXPECT_EQ(std::make_pair(c, id), std::make_pair(std::uint8_t{0x06}, std::uint8_t{0x8A})) << "not a CFG-VALSET";
  EXPECT_EQ(s.total, s.rtcm_bytes + s.ubx_bytes) << "bytes outside any frame were written";
}

std::map<std::uint16_t, std::int64_t> by_message(const std::vector<Bytes>& frames) {
  std::map<std::uint16_t, std::int64_t> out;
  for (const Bytes& f : frames)
    ++out[framing::rtcm3_message_number(f)];
  return out;
}

struct Rig {
  std::vector<Bytes> frames;
  std::string rover;
};

// The final status: every frame counted by type, the CRC failures, none lost.
void expect_status(Listener& listener, const std::vector<Bytes>& frames, std::size_t corrupted,
                   const std::string& state_start) {
  ASSERT_TRUE(listener.wait_for(
      [&] {
        return !listener.statuses.empty() && counter(listener.statuses.back(), "corrections.written_frames") ==
                                                 static_cast<std::int64_t>(frames.size());
      },
      std::chrono::seconds(5)));
  const std::lock_guard lock(listener.mutex);
  const status_t& s = listener.statuses.back();
  EXPECT_EQ(s.corrections.rfind(state_start, 0), 0U) << s.corrections;
  EXPECT_EQ(counter(s, "corrections.frames"), static_cast<std::int64_t>(frames.size()));
  EXPECT_EQ(counter(s, "corrections.crc_errors"), static_cast<std::int64_t>(corrupted));
  EXPECT_EQ(counter(s, "corrections.write_failures"), 0);
  EXPECT_EQ(counter(s, "corrections.ring_drops"), 0);
  for (const auto& [number, count] : by_message(frames))
    EXPECT_EQ(counter(s, "corrections.rtcm." + std::to_string(number)), count) << number;
  EXPECT_TRUE(std::isfinite(s.correction_age_s));
  EXPECT_LT(s.correction_age_s, 10.0);
  // The rover: the F9R's float solution; fixed is required, so the pose is withheld, named.
  EXPECT_EQ(s.rtk_solution, status_t::RTK_FLOAT);
  EXPECT_FALSE(s.pose_valid);
  EXPECT_NE(s.pose_status.find("GNSS carrier solution float, fixed required (pose.require_rtk)"), std::string::npos)
      << s.pose_status;
}

#define REQUIRE_RIG(rig)                                                                                       \
  REQUIRE_STREAM_PEERS();                                                                                      \
  TRAJROI_REQUIRE_DATA(corrections_path, "ublox/gpsd/ublox-zed-f9t-rtcm3.log");                                \
  TRAJROI_REQUIRE_DATA(rover_path, "ublox/gpsd/ublox-zed-f9r.log");                                            \
  const Rig rig{log_frames(trajroi::test::read_file(corrections_path)), trajroi::test::read_file(rover_path)}; \
  ASSERT_EQ(rig.frames.size(), 182U)

TEST(TrajroidCorrections, NtripCasterFramesReachTheReceiverExactlyOnceAcrossARestart) {
  REQUIRE_RIG(rig);
  const std::uint16_t input = free_port(), port = free_port();
  Caster caster(input, port);
  Receiver rx(rig.rover, std::chrono::milliseconds(1000));
  const std::string prefix = "RTK_NTRIP";
  const fs::path dir =
      write_config(prefix, rx.path(), "ntrip://rover:s3cret@127.0.0.1:" + std::to_string(port) + "/F9T?version=1");
  Listener listener(prefix);
  const fs::path log = dir / "trajroid.log";
  Child trajroid(trajroid_args(dir), log);
  ASSERT_TRUE(log_says(log, "corrections: connected to ntrip://rover:***@127.0.0.1:" + std::to_string(port)))
      << daemon_test::slurp(log);
  EXPECT_TRUE(log_says(log, "RTCM3 corrections accepted")) << daemon_test::slurp(log);
  std::size_t corrupted = 0;
  caster.write(with_noise(rig.frames, 0, 91, corrupted));
  ASSERT_TRUE(wait_frames(rx, 91)) << rx.split().rtcm.size() << " frames\n" << daemon_test::slurp(log);
  // The caster goes away and comes back: said, reconnected, nothing written twice.
  caster.close_inputs();
  caster.stop();
  ASSERT_TRUE(log_says(log, "the caster closed the connection")) << daemon_test::slurp(log);
  caster.start();
  ASSERT_TRUE(log_says(log, "corrections: connected to ntrip://", 2, 20.0)) << daemon_test::slurp(log);
  caster.write(with_noise(rig.frames, 91, 182, corrupted));
  ASSERT_TRUE(wait_frames(rx, 182)) << rx.split().rtcm.size() << " frames\n" << daemon_test::slurp(log);
  expect_status(listener, rig.frames, corrupted, "streaming from ntrip://rover:***@127.0.0.1:");
  {
    const std::lock_guard lock(listener.mutex);
    EXPECT_GE(counter(listener.statuses.back(), "corrections.gga_sent"), 1);
    EXPECT_EQ(counter(listener.statuses.back(), "corrections.connects"), 2);
  }
  EXPECT_TRUE(log_says(log, "RTK float")) << daemon_test::slurp(log);
  EXPECT_TRUE(log_says(log, "RTCM3 frames failed their CRC-24Q since the start (line noise on the link?)"))
      << daemon_test::slurp(log);
  trajroid.signal(SIGTERM);
  EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0) << daemon_test::slurp(log);
  expect_exactly(rx, rig.frames);
  // The password never reaches the log.
  EXPECT_EQ(daemon_test::slurp(log).find("s3cret"), std::string::npos);
  fs::remove_all(dir);
}

TEST(TrajroidCorrections, WrongCredentialsAreNamedAndNothingIsWritten) {
  REQUIRE_RIG(rig);
  const std::uint16_t input = free_port(), port = free_port();
  Caster caster(input, port);
  Receiver rx(rig.rover, std::chrono::milliseconds(1000));
  const std::string prefix = "RTK_REFUSED";
  const fs::path dir =
      write_config(prefix, rx.path(), "ntrip://rover:wrong@127.0.0.1:" + std::to_string(port) + "/F9T?version=1");
  const fs::path log = dir / "trajroid.log";
  Child trajroid(trajroid_args(dir), log);
  EXPECT_TRUE(log_says(log, "refused by the caster: HTTP/1.0 401 Unauthorized")) << daemon_test::slurp(log);
  std::size_t corrupted = 0;
  caster.write(with_noise(rig.frames, 0, 20, corrupted));
  // Past the age limit with nothing written: warned, with the caster's answer.
  EXPECT_TRUE(log_says(log, "corrections lost for")) << daemon_test::slurp(log);
  trajroid.signal(SIGTERM);
  EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0);
  EXPECT_TRUE(rx.split().rtcm.empty());
  fs::remove_all(dir);
}

// Raw streams: str2str's TCP server, socat's UDP datagrams.
TEST(TrajroidCorrections, TcpAndUdpStreamsReachTheReceiverExactly) {
  REQUIRE_RIG(rig);
  for (const std::string kind : {"tcp", "udp"}) {
    SCOPED_TRACE(kind);
    const std::uint16_t input = free_port(), port = free_port();
    Caster server =
        kind == "tcp" ? Caster(input, "tcpsvr://:" + std::to_string(port)) : Caster::udp_sender(input, port);
    Receiver rx(rig.rover, std::chrono::milliseconds(1000));
    const std::string prefix = "RTK_" + kind;
    const std::string url =
        kind == "tcp" ? "tcp://127.0.0.1:" + std::to_string(port) : "udp://127.0.0.1:" + std::to_string(port);
    const fs::path dir = write_config(prefix, rx.path(), url);
    Listener listener(prefix);
    const fs::path log = dir / "trajroid.log";
    Child trajroid(trajroid_args(dir), log);
    ASSERT_TRUE(log_says(log, kind == "tcp" ? "corrections: connected to tcp://" : "corrections: from udp://"))
        << daemon_test::slurp(log);
    std::size_t corrupted = 0;
    server.write(with_noise(rig.frames, 0, 182, corrupted));
    ASSERT_TRUE(wait_frames(rx, 182)) << rx.split().rtcm.size() << " frames\n" << daemon_test::slurp(log);
    expect_status(listener, rig.frames, corrupted, "streaming from " + url);
    trajroid.signal(SIGTERM);
    EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0) << daemon_test::slurp(log);
    expect_exactly(rx, rig.frames);
    server.close_inputs();
    fs::remove_all(dir);
  }
}

// A stream that is not RTCM3 (a VN-100's binary output wired to the radio port by mistake): named,
// nothing written.
TEST(TrajroidCorrections, AStreamThatIsNotRtcm3IsNamedAndNothingIsWritten) {
  REQUIRE_RIG(rig);
  TRAJROI_REQUIRE_DATA(vn100_path, "vectornav/LoggerWavesInIce_F00379.raw");
  const std::string vn100 = trajroi::test::read_file(vn100_path);
  const std::uint16_t input = free_port(), port = free_port();
  Caster server(input, "tcpsvr://:" + std::to_string(port));
  Receiver rx(rig.rover, std::chrono::milliseconds(1000));
  const std::string prefix = "RTK_NOT_RTCM3";
  const std::string url = "tcp://127.0.0.1:" + std::to_string(port);
  const fs::path dir = write_config(prefix, rx.path(), url);
  const fs::path log = dir / "trajroid.log";
  Child trajroid(trajroid_args(dir), log);
  ASSERT_TRUE(log_says(log, "corrections: connected to tcp://")) << daemon_test::slurp(log);
  // Four seconds of the VN-100's output, a piece each second.
  for (int second = 0; second < 4; ++second) {
    const std::size_t at = static_cast<std::size_t>(second) * 4096;
    server.write(
        Bytes(vn100.begin() + static_cast<std::ptrdiff_t>(at), vn100.begin() + static_cast<std::ptrdiff_t>(at + 4096)));
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  }
  EXPECT_TRUE(log_says(log, "and no RTCM3 frame in 3 s (streaming from " + url +
                                "): is the source's output RTCM 3 (not RTCM 2, CMR or a receiver's own messages)"))
      << daemon_test::slurp(log);
  trajroid.signal(SIGTERM);
  EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0) << daemon_test::slurp(log);
  EXPECT_TRUE(rx.split().rtcm.empty());
  server.close_inputs();
  fs::remove_all(dir);
}

// A radio modem's serial port (serial://): a pseudo-terminal the test writes the base's frames
// into as a 57600-baud radio link delivers them, in pieces with noise between.
TEST(TrajroidCorrections, ARadioSerialPortReachesTheReceiverExactly) {
  REQUIRE_RIG(rig);
  const int radio = posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(radio, 0);
  ASSERT_EQ(grantpt(radio), 0);
  ASSERT_EQ(unlockpt(radio), 0);
  termios t{};
  ASSERT_EQ(tcgetattr(radio, &t), 0);
  cfmakeraw(&t);
  ASSERT_EQ(tcsetattr(radio, TCSANOW, &t), 0);
  const std::string url = std::string("serial://") + ptsname(radio) + "?baud=57600";
  Receiver rx(rig.rover, std::chrono::milliseconds(1000));
  const std::string prefix = "RTK_RADIO";
  const fs::path dir = write_config(prefix, rx.path(), url);
  Listener listener(prefix);
  const fs::path log = dir / "trajroid.log";
  Child trajroid(trajroid_args(dir), log);
  // trajroid is up (its first status) and has opened the radio's port.
  ASSERT_TRUE(listener.wait_for([&] { return !listener.statuses.empty(); }, std::chrono::seconds(10)))
      << daemon_test::slurp(log);
  std::size_t corrupted = 0;
  const Bytes bytes = with_noise(rig.frames, 0, 182, corrupted);
  for (std::size_t at = 0; at < bytes.size(); at += 256) {
    const std::size_t n = std::min<std::size_t>(256, bytes.size() - at);
    ASSERT_EQ(write(radio, bytes.data() + at, n), static_cast<ssize_t>(n));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(wait_frames(rx, 182)) << rx.split().rtcm.size() << " frames\n" << daemon_test::slurp(log);
  EXPECT_TRUE(log_says(log, "corrections: receiving corrections on " + url)) << daemon_test::slurp(log);
  expect_status(listener, rig.frames, corrupted, "streaming from " + url);
  trajroid.signal(SIGTERM);
  EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0) << daemon_test::slurp(log);
  expect_exactly(rx, rig.frames);
  close(radio);
  fs::remove_all(dir);
}

// rtcm_t on LCM, published with liblcm by a "base station" elsewhere: the frames cut at
// arbitrary points across messages, noise and corrupted copies between them.
TEST(TrajroidCorrections, LcmRtcmMessagesReachTheReceiverExactly) {
  REQUIRE_RIG(rig);
  Receiver rx(rig.rover, std::chrono::milliseconds(1000));
  const std::string prefix = "RTK_LCM";
  const fs::path dir = write_config(prefix, rx.path(), "lcm://" + prefix + "_RTCM");
  Listener listener(prefix);
  const fs::path log = dir / "trajroid.log";
  Child trajroid(trajroid_args(dir), log);
  ASSERT_TRUE(log_says(log, "corrections: from lcm://" + prefix + "_RTCM")) << daemon_test::slurp(log);
  std::size_t corrupted = 0;
  const Bytes bytes = with_noise(rig.frames, 0, 182, corrupted);
  lcm::LCM base(daemon_test::kTestLcmUrl);
  ASSERT_TRUE(base.good());
  // A message of another type on the channel first: counted, named, not used.
  status_t other{};
  base.publish(prefix + "_RTCM", &other);
  for (std::size_t at = 0; at < bytes.size(); at += 700) {
    rtcm_t m;
    m.source = "base-station-1";
    m.data.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                  bytes.begin() + static_cast<std::ptrdiff_t>(std::min(bytes.size(), at + 700)));
    m.num_bytes = static_cast<std::int32_t>(m.data.size());
    base.publish(prefix + "_RTCM", &m);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(wait_frames(rx, 182)) << rx.split().rtcm.size() << " frames\n" << daemon_test::slurp(log);
  expect_status(listener, rig.frames, corrupted, "streaming from LCM " + prefix + "_RTCM (base-station-1)");
  EXPECT_TRUE(log_says(log, "is not an rtcm_t")) << daemon_test::slurp(log);
  trajroid.signal(SIGTERM);
  EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0) << daemon_test::slurp(log);
  expect_exactly(rx, rig.frames);
  fs::remove_all(dir);
}

}  // namespace
