#pragma once

// A u-blox receiver for trajroid's live tests: the other side of a pseudo-terminal playing a
// real UBX log at its recorded pace, acknowledging trajroid's configuration, keeping every byte
// trajroid writes into the port.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "daemon_fixture.hpp"
#include "trajroi/framing/rtcm3.hpp"
#include "trajroi/ublox/config.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"

namespace trajroi::corrections_test {

// The u-blox side of a pseudo-terminal: plays `log` one navigation epoch (up to and with each
// NAV-PVT) per `epoch` (the ZED-F9R log's 1 Hz), over again at its end; acknowledges every
// CFG message trajroid writes; keeps every byte trajroid writes.
class Receiver {
 public:
  Receiver(const std::string& log, std::chrono::milliseconds epoch) : epoch_(epoch) {
    master_ = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    EXPECT_GE(master_, 0);
    EXPECT_EQ(grantpt(master_), 0);
    EXPECT_EQ(unlockpt(master_), 0);
    path_ = ptsname(master_);
    // Raw from the start: a line discipline still in its default mode (before trajroid opens the
    // port) would echo the receiver's own bytes back as if trajroid had written them.
    termios t{};
    EXPECT_EQ(tcgetattr(master_, &t), 0);
    cfmakeraw(&t);
    EXPECT_EQ(tcsetattr(master_, TCSANOW, &t), 0);
    // Epochs: the bytes up to the end of each NAV-PVT.
    std::size_t from = 0;
    for (std::size_t at = log.find("\xB5\x62\x01\x07"); at != std::string::npos;
         at = log.find("\xB5\x62\x01\x07", at + 4)) {
      if (at + 6 > log.size()) break;
      const std::size_t length = static_cast<std::size_t>(static_cast<std::uint8_t>(log[at + 4]) |
                                                          static_cast<std::uint8_t>(log[at + 5]) << 8);
      const std::size_t end = std::min(log.size(), at + 8 + length);
      epochs_.emplace_back(log.begin() + static_cast<std::ptrdiff_t>(from),
                           log.begin() + static_cast<std::ptrdiff_t>(end));
      from = end;
    }
    thread_ = std::thread([this] { serve(); });
  }
  ~Receiver() {
    stop_ = true;
    thread_.join();
    close(master_);
  }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::vector<std::uint8_t> written() {
    const std::lock_guard lock(mutex_);
    return written_;
  }
  // The RTCM3 frames among the bytes written, and the UBX frames (class, id) with them.
  struct Split {
    std::vector<std::vector<std::uint8_t>> rtcm;
    std::vector<std::pair<std::uint8_t, std::uint8_t>> ubx;
    std::size_t rtcm_bytes = 0, ubx_bytes = 0, total = 0;
  };
  Split split() {
    const std::vector<std::uint8_t> all = written();
    Split s;
    s.total = all.size();
    framing::Rtcm3Framer rtcm;
    rtcm.feed(all, [&](std::span<const std::uint8_t> f) {
      s.rtcm.emplace_back(f.begin(), f.end());
      s.rtcm_bytes += f.size();
    });
    ublox::Framer ubx;
    ubx.feed(all, [&](const ublox::Message& m) {
      s.ubx.emplace_back(m.msg_class, m.msg_id);
      s.ubx_bytes += m.payload.size() + 8;
    });
    return s;
  }

 private:
  void serve() {
    ublox::Framer framer;
    auto next_epoch = std::chrono::steady_clock::now();
    std::size_t epoch = 0;
    std::uint8_t buffer[4096];
    while (!stop_) {
      if (std::chrono::steady_clock::now() >= next_epoch && !epochs_.empty()) {
        const std::string& bytes = epochs_[epoch++ % epochs_.size()];
        (void)!write(master_, bytes.data(), bytes.size());
        next_epoch += epoch_;
      }
      pollfd p{master_, POLLIN, 0};
      if (poll(&p, 1, 10) <= 0 || (p.revents & POLLIN) == 0) continue;
      const ssize_t n = read(master_, buffer, sizeof buffer);
      if (n <= 0) continue;
      const std::span<const std::uint8_t> got(buffer, static_cast<std::size_t>(n));
      {
        const std::lock_guard lock(mutex_);
        written_.insert(written_.end(), got.begin(), got.end());
      }
      framer.feed(got, [&](const ublox::Message& m) {
        if (m.msg_class != 0x06) return;
        const std::vector<std::uint8_t> payload{m.msg_class, m.msg_id};
        const auto ack = ublox::encode_frame(ublox::kClassAck, 0x01, payload);
        (void)!write(master_, ack.data(), ack.size());
      });
    }
  }
  std::chrono::milliseconds epoch_;
  std::vector<std::string> epochs_;
  int master_ = -1;
  std::string path_;
  std::mutex mutex_;
  std::vector<std::uint8_t> written_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// A run folder for trajroid reading the pseudo-terminal receiver at `device`, the pose from the
// GNSS alone (a 10 m trajectory at the F9R log's site), LCM channels `prefix`_*: `gnss` and
// `pose` are lines added under those keys, `extra` whole sections.
inline std::filesystem::path write_rover_config(const std::string& prefix, const std::string& device,
                                                const std::string& gnss, const std::string& pose,
                                                const std::string& extra = "") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / (prefix + "_" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "trajectory.csv") << "0,0\n10,0\n";
  std::ofstream(dir / "trajroid.yaml")
      << "global_frame:\n  origin: {lat_deg: 45.0657, lon_deg: 7.6590, height_m: 300.0}\n"
      << "trajectory:\n  file: trajectory.csv\n"
      << "lidar:\n  data_port: 0\n  position_port: 0\n"
      << "gnss:\n  device: " << device << "\n"
      << gnss << "pose:\n  source: gnss\n  gnss_heading: {initial_heading_deg: 90}\n"
      << pose << extra << "lcm:\n  channels: {points: " << prefix << "_POINTS, pose: " << prefix
      << "_POSE, roi: " << prefix << "_ROI, status: " << prefix << "_STATUS, trajectory: " << prefix
      << "_TRAJECTORY, active_trajectory: " << prefix << "_ACTIVE}\n";
  return dir;
}

// trajroid's arguments for the run folder `dir` on the tests' LCM URL (its log: dir/trajroid.log).
inline std::vector<std::string> trajroid_args(const std::filesystem::path& dir) {
  return {"--config", (dir / "trajroid.yaml").string(), "--lcm-url", daemon_test::kTestLcmUrl};
}

// Waits until the log holds `text` at least `times` times.
inline bool log_says(const std::filesystem::path& log, const std::string& text, int times = 1, double seconds = 15.0) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<int>(seconds * 1000));
  while (std::chrono::steady_clock::now() < until) {
    const std::string s = daemon_test::slurp(log);
    int n = 0;
    for (std::size_t at = s.find(text); at != std::string::npos; at = s.find(text, at + 1))
      ++n;
    if (n >= times) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

}  // namespace trajroi::corrections_test
