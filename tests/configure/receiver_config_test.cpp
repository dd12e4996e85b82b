// Receiver configuration through a pseudo-terminal, against scripted devices that answer as a
// u-blox F9, a u-blox M8 (no CFG-VALSET; NAV-HPPOSLLH refused on a plain M8), one that NAKs,
// one that says nothing, and a VN-100 that echoes, refuses ($VNERR) or reads back something
// else. The library, the `trajroi configure` command and trajroid's gnss.configure.
#include "trajroi/configure/receiver_config.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "test_data.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vn100/command.hpp"

namespace {

using namespace trajroi;

// A pseudo-terminal whose master side a thread serves with `answer` (bytes in → bytes out).
class ScriptedDevice {
 public:
  using Answer = std::function<std::vector<std::uint8_t>(std::span<const std::uint8_t>)>;
  explicit ScriptedDevice(Answer answer) : answer_(std::move(answer)) {
    master_ = posix_openpt(O_RDWR | O_NOCTTY);
    EXPECT_GE(master_, 0);
    EXPECT_EQ(grantpt(master_), 0);
    EXPECT_EQ(unlockpt(master_), 0);
    path_ = ptsname(master_);
    thread_ = std::thread([this] { serve(); });
  }
  ~ScriptedDevice() {
    stop_ = true;
    thread_.join();
    close(master_);
  }
  [[nodiscard]] const std::string& path() const { return path_; }
  std::vector<std::string> received;  // what each chunk was (for the log of a failure)

 private:
  void serve() {
    std::uint8_t buffer[4096];
    while (!stop_) {
      pollfd p{master_, POLLIN, 0};
      if (poll(&p, 1, 20) <= 0 || (p.revents & POLLIN) == 0) continue;
      const ssize_t n = read(master_, buffer, sizeof buffer);
      if (n <= 0) continue;
      const std::vector<std::uint8_t> reply =
          answer_(std::span<const std::uint8_t>(buffer, static_cast<std::size_t>(n)));
      if (!reply.empty()) (void)!write(master_, reply.data(), reply.size());
    }
  }
  Answer answer_;
  int master_ = -1;
  std::string path_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// A u-blox: each UBX message in gets `verdict(class, id, payload)`: 1 ACK-ACK, 0 ACK-NAK, -1 silence.
ScriptedDevice::Answer ublox_device(
    std::function<int(std::uint8_t, std::uint8_t, std::span<const std::uint8_t>)> verdict) {
  auto framer = std::make_shared<ublox::Framer>();
  return [framer, verdict](std::span<const std::uint8_t> in) {
    std::vector<std::uint8_t> out;
    framer->feed(in, [&](const ublox::Message& m) {
      const int v = verdict(m.msg_class, m.msg_id, m.payload);
      if (v < 0) return;
      const std::vector<std::uint8_t> payload{m.msg_class, m.msg_id};
      const auto ack = ublox::encode_frame(ublox::kClassAck, v == 1 ? 0x01 : 0x00, payload);
      out.insert(out.end(), ack.begin(), ack.end());
    });
    return out;
  };
}

constexpr std::uint8_t kClassCfg = 0x06, kIdValset = 0x8A, kIdMsg = 0x01, kIdRate = 0x08;

configure::Result run_ublox(ScriptedDevice& device, bool rtcm3_input = false) {
  serial::SerialPortOptions o;
  o.device = device.path();
  serial::SerialPortSource port(o);
  configure::UbloxSettings s;
  s.timeout = std::chrono::milliseconds(300);
  s.port = ublox::Port::kUart1;
  s.rtcm3_input = rtcm3_input;
  return configure::configure_ublox(port, s);
}

std::string steps(const configure::Result& r) {
  std::string out = r.summary + "\n";
  for (const auto& s : r.steps)
    out += (s.ok ? "ok " : "FAIL ") + s.what + ": " + s.answer + "\n";
  return out;
}

TEST(ReceiverConfig, AnF9TakesOneValsetAndAcksIt) {
  std::vector<std::pair<std::uint8_t, std::uint8_t>> seen;
  ScriptedDevice f9(ublox_device([&](std::uint8_t c, std::uint8_t i, auto) {
    seen.emplace_back(c, i);
    return 1;
  }));
  const configure::Result r = run_ublox(f9);
  EXPECT_TRUE(r.ok) << steps(r);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], std::make_pair(kClassCfg, kIdValset));
  EXPECT_NE(r.summary.find("u-blox F9 configured: NAV-PVT, NAV-HPPOSLLH at 5 Hz on UART1"), std::string::npos)
      << r.summary;
}

// gnss.corrections: a second CFG-VALSET sets CFG-UART1INPROT-RTCM3X (0x10730004, the interface
// description's key) to 1; its ACK is checked, a NAK named.
TEST(ReceiverConfig, RtcmInputIsSetOnThePortAndItsRefusalNamed) {
  for (const bool accept : {true, false}) {
    std::vector<std::vector<std::uint8_t>> valsets;
    ScriptedDevice f9(ublox_device([&](std::uint8_t c, std::uint8_t i, std::span<const std::uint8_t> payload) {
      if (c == kClassCfg && i == kIdValset) valsets.emplace_back(payload.begin(), payload.end());
      return valsets.size() == 2 && !accept ? 0 : 1;
    }));
    const configure::Result r = run_ublox(f9, true);
    ASSERT_EQ(valsets.size(), 2U) << steps(r);
    // version 0, layer RAM, 2 reserved, key 0x10730004 little-endian, value 1 (one byte: L).
    EXPECT_EQ(valsets[1], (std::vector<std::uint8_t>{0, 1, 0, 0, 0x04, 0x00, 0x73, 0x10, 1})) << steps(r);
    EXPECT_EQ(r.ok, accept) << steps(r);
    EXPECT_NE(r.summary.find(accept ? "RTCM3 corrections accepted" : "RTCM3 input refused (ACK-NAK)"),
              std::string::npos)
        << r.summary;
  }
}

TEST(ReceiverConfig, AnM8GetsCfgRateAndCfgMsgAndMayRefuseHighPrecision) {
  ScriptedDevice m8(ublox_device([](std::uint8_t c, std::uint8_t i, std::span<const std::uint8_t> payload) {
    if (c == kClassCfg && i == kIdValset) return -1;  // unknown to an M8: no answer
    if (c == kClassCfg && i == kIdMsg && payload.size() >= 2 && payload[1] == 0x14) return 0;  // HPPOSLLH: NAK
    return 1;
  }));
  const configure::Result r = run_ublox(m8);
  EXPECT_TRUE(r.ok) << steps(r);
  EXPECT_NE(r.summary.find("u-blox M8 configured"), std::string::npos) << r.summary;
  EXPECT_NE(r.summary.find("NAV-HPPOSLLH refused: ACK-NAK"), std::string::npos) << r.summary;
}

TEST(ReceiverConfig, ANakOrSilenceIsAFailureNamed) {
  ScriptedDevice naks(ublox_device([](std::uint8_t c, std::uint8_t i, auto) {
    return c == kClassCfg && i == kIdRate ? 1 : 0;  // CFG-RATE taken, CFG-MSG NAV-PVT refused
  }));
  configure::Result r = run_ublox(naks);
  EXPECT_FALSE(r.ok);
  bool named = false;
  for (const auto& s : r.steps)
    named = named || (!s.ok && s.what.find("NAV-PVT") != std::string::npos && s.answer == "ACK-NAK");
  EXPECT_TRUE(named) << steps(r);

  ScriptedDevice silent(ublox_device([](auto, auto, auto) { return -1; }));
  r = run_ublox(silent);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.summary.find("no u-blox answered (CFG-VALSET: no answer within 300 ms; CFG-RATE: no answer within 300 ms)"
                           ": wrong device or baud rate?"),
            std::string::npos)
      << r.summary;
}

// A VN-100: echoes $VNWRG (or refuses it), answers $VNRRG with `stored` (the written values,
// unless `read_back` replaces them).
ScriptedDevice::Answer vn100_device(bool refuse, std::string read_back = {}) {
  auto text = std::make_shared<std::string>();
  auto stored = std::make_shared<std::string>();
  return [=](std::span<const std::uint8_t> in) {
    text->append(in.begin(), in.end());
    std::string out;
    for (std::size_t end; (end = text->find("\r\n")) != std::string::npos;) {
      const std::string line = text->substr(0, end);
      text->erase(0, end + 2);
      const std::string body = line.substr(1, line.find('*') - 1);
      if (body.rfind("VNWRG,75,", 0) == 0) {
        if (refuse) {
          out += vn100::ascii_command("VNERR,03");
        } else {
          *stored = body.substr(std::string("VNWRG,75,").size());
          out += vn100::ascii_command(body);
        }
      } else if (body == "VNRRG,75") {
        out += vn100::ascii_command("VNRRG,75," + (read_back.empty() ? *stored : read_back));
      }
    }
    // Binary frames keep coming meanwhile: noise the answer must be found among.
    out = std::string("\xFA\x01\x09\x00garbage$VN", 13) + out;
    return std::vector<std::uint8_t>(out.begin(), out.end());
  };
}

configure::Result run_vn100(ScriptedDevice& device) {
  serial::SerialPortOptions o;
  o.device = device.path();
  serial::SerialPortSource port(o);
  configure::Vn100Settings s;
  s.timeout = std::chrono::milliseconds(300);
  return configure::configure_vn100(port, s);
}

TEST(ReceiverConfig, AVn100RegisterIsWrittenAndReadBack) {
  ScriptedDevice vn(vn100_device(false));
  configure::Result r = run_vn100(vn);
  EXPECT_TRUE(r.ok) << steps(r);
  EXPECT_NE(r.summary.find("VN-100 configured: VNWRG,75,3,20,01,0009 (TimeStartup + YawPitchRoll at 40 Hz)"),
            std::string::npos)
      << r.summary;

  ScriptedDevice refusing(vn100_device(true));
  r = run_vn100(refusing);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.summary.find("not written: $VNERR,03"), std::string::npos) << r.summary;

  ScriptedDevice other(vn100_device(false, "3,80,01,0008"));
  r = run_vn100(other);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.summary.find("read back $VNRRG,75,3,80,01,0008, not what was written (VNWRG,75,3,20,01,0009)"),
            std::string::npos)
      << r.summary;
}

TEST(ReceiverConfig, TheConfigureCommandReportsAndExitsByTheOutcome) {
  ScriptedDevice f9(ublox_device([](auto, auto, auto) { return 1; }));
  const std::string out = ::trajroi::test::scratch_path("configure_cli.txt").string();
  int status = std::system(
      (std::string(TRAJROI_CLI) + " configure gnss --device " + f9.path() + " --rate 10 > " + out + " 2>&1").c_str());
  EXPECT_EQ(WEXITSTATUS(status), 0);
  ScriptedDevice silent(ublox_device([](auto, auto, auto) { return -1; }));
  status = std::system(
      (std::string(TRAJROI_CLI) + " configure gnss --device " + silent.path() + " --timeout-ms 200 >> " + out + " 2>&1")
          .c_str());
  EXPECT_EQ(WEXITSTATUS(status), 1);
  std::FILE* f = std::fopen(out.c_str(), "r");
  ASSERT_NE(f, nullptr);
  std::string text(4096, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fclose(f);
  std::remove(out.c_str());
  EXPECT_NE(text.find("ok   CFG-VALSET (F9): NAV-PVT, NAV-HPPOSLLH at 10 Hz on UART1: ACK-ACK"), std::string::npos)
      << text;
  EXPECT_NE(text.find("FAIL CFG-RATE (M8): 5 Hz: no answer within 200 ms"), std::string::npos) << text;
}

// trajroid with gnss.configure: the receiver is configured when its device opens, and the
// outcome is in the log with the open.
TEST(ReceiverConfig, TrajroidConfiguresTheReceiverWhenItsDeviceOpens) {
  ScriptedDevice f9(ublox_device([](auto, auto, auto) { return 1; }));
  const std::string dir = ::testing::TempDir() + "trajroid_configure_" + std::to_string(getpid());
  (void)std::system(("mkdir -p " + dir).c_str());
  {
    std::FILE* f = std::fopen((dir + "/trajectory.csv").c_str(), "w");
    std::fputs("0,0\n10,0\n", f);
    std::fclose(f);
    f = std::fopen((dir + "/trajroid.yaml").c_str(), "w");
    std::fprintf(f,
                 "global_frame:\n  origin: {lat_deg: 50.0, lon_deg: 14.0, height_m: 300.0}\n"
                 "trajectory:\n  file: trajectory.csv\n"
                 "lidar:\n  data_port: 0\n  position_port: 0\n"
                 "gnss:\n  device: %s\n  configure: true\n  rate_hz: 10\n"
                 "pose:\n  source: gnss\n",
                 f9.path().c_str());
    std::fclose(f);
  }
  const std::string log = dir + "/trajroid.log";
  const int status = std::system(("timeout --preserve-status -s TERM 3 " + std::string(TRAJROID) + " --config " + dir +
                                  "/trajroid.yaml --lcm-url 'udpm://239.255.76.67:7667?ttl=0' 2> " + log)
                                     .c_str());
  EXPECT_EQ(WEXITSTATUS(status), 0);
  std::FILE* f = std::fopen(log.c_str(), "r");
  ASSERT_NE(f, nullptr);
  std::string text(1 << 16, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fclose(f);
  EXPECT_NE(text.find("gnss: " + f9.path() + " @ 115200 open (termios backend); " + f9.path() +
                      " @ 115200: u-blox F9 configured: NAV-PVT, NAV-HPPOSLLH, NAV-RELPOSNED at 10 Hz on UART1"),
            std::string::npos)
      << text;
  (void)std::system(("rm -rf " + dir).c_str());
}

}  // namespace
