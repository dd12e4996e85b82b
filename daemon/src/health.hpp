#pragma once

// Every fault named: once a second the publisher hands each status snapshot here; a fault
// seen over the last few seconds (the counters' change since then) is said in one log line
// with its figures and its remedy when it starts — within 5 s of the start or of the fault —
// and once more when it ends. The same look gives systemd's STATUS= its words: each input that
// is missing or wrong, by name, and only the inputs the pose source uses ("waiting for LiDAR
// data on UDP port 2368; GNSS: NMEA text, no UBX, from /dev/ttyACM0", "no valid pose: newest
// localization pose too old: …", "publishing 10.0 sweeps/s"). A mix of VLP-16 packets and
// other datagrams on the LiDAR port is summarised once a minute.
#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "status.hpp"
#include "trajroi/daemon/config.hpp"

namespace trajroi::daemon {

struct HealthLine {
  enum class Level : std::uint8_t { kInfo, kWarning } level = Level::kWarning;
  std::string text;
};

class HealthMonitor {
 public:
  // `live`: the inputs are sensors (a replay has no silent sensor to report).
  HealthMonitor(const DaemonConfig& config, bool live, std::int64_t start_steady_ns);

  // The lines to log for this snapshot (faults starting or ending).
  [[nodiscard]] std::vector<HealthLine> update(const StatusSnapshot& s);
  // Several LiDARs: the lines for the sensors silent as a sweep went out (SweepHeader::silent),
  // said at once (the snapshots come once a second).
  [[nodiscard]] std::vector<HealthLine> silent_lidars(std::uint32_t silent);
  // The state in words, for STATUS=.
  [[nodiscard]] const std::string& state() const noexcept { return state_; }

  // A fault is judged over at least this much history (the lines come within 5 s).
  static constexpr std::int64_t kWindow_ns = 3'000'000'000;
  static constexpr std::int64_t kJitter_ns = 100'000'000;

 private:
  enum Fault : std::uint8_t {
    kLidarSilent,
    kLidarForeignOnly,
    kLidarNotVlp16Only,
    kGnssSilent,
    kGnssNoFrames,
    kGnssNoPvt,
    kImuSilent,
    kImuNoFrames,
    kImuNoAttitude,
    kLocalizationSilent,
    kLocalizationInvalid,
    kLocalizationMalformed,
    kTrajectoryFar,
    kClockOffset,
    kLidarClockOffset,
    kLidarPpsLost,
    kRingDrops,
    kFaultCount
  };
  // Raises or clears `fault`: true → the warning (once, as it starts); false → the info line
  // (once, as it ends) when `ended` is given.
  void set(Fault fault, bool active, std::string warning, std::string ended, std::vector<HealthLine>& out);
  // The faults of each kind of input (health.cpp, health_pose_inputs.cpp).
  void lidar(const StatusSnapshot& s, std::vector<HealthLine>& out);
  void serial_ports(const StatusSnapshot& s, std::vector<HealthLine>& out);
  void localization(const StatusSnapshot& s, std::vector<HealthLine>& out);
  void minute_summary(const StatusSnapshot& s, std::vector<HealthLine>& out);
  // The rings between the threads: a drop named with its ring (health_rings.cpp).
  void rings(const StatusSnapshot& s, std::vector<HealthLine>& out);
  // Several LiDARs: each one that falls silent or sends again, said.
  void lidar_sensors(std::uint32_t silent, std::vector<HealthLine>& out);
  [[nodiscard]] std::string lidar_names(std::uint32_t mask) const;
  // Several LiDARs: where LiDAR `lane` sends from and to, "10.0.0.102 → UDP 2368".
  [[nodiscard]] std::string lidar_where(std::size_t lane) const;
  // How a line names LiDAR `lane`: for one, "" and "the VLP-16's" (its model, once known);
  // with several, "rear (10.0.0.102 → UDP 2368): " and "the rear LiDAR's (10.0.0.102 → UDP 2368)".
  [[nodiscard]] std::string lidar_prefix(std::size_t lane) const;
  [[nodiscard]] std::string lidar_possessive(const StatusSnapshot& s, std::size_t lane) const;
  // The host clock against GNSS time and each LiDAR's; each LiDAR's PPS (health_clocks.cpp).
  void clocks(const StatusSnapshot& s, std::vector<HealthLine>& out);
  // "LiDAR rear (10.0.0.102 → UDP 2368): packets rejected: <why>" for each LiDAR whose packets
  // since `base` were all rejected for their model ("LiDAR: …" for one); "" for none.
  [[nodiscard]] std::string rejecting_lidars(const StatusSnapshot& s, const StatusSnapshot& base) const;
  // The state in words, from the faults now active.
  void update_state(const StatusSnapshot& s, const StatusSnapshot& previous);
  // The counters' change over the window (the oldest snapshot kept to `s`).
  [[nodiscard]] std::uint64_t delta(const StatusSnapshot& s, Counter c) const noexcept {
    return s[c] - history_.front()[c];
  }
  [[nodiscard]] double window_s(const StatusSnapshot& s) const noexcept {
    return static_cast<double>(s.steady_ns - history_.front().steady_ns) * 1e-9;
  }
  [[nodiscard]] bool judged(const StatusSnapshot& s) const noexcept {
    return s.steady_ns - history_.front().steady_ns >= kWindow_ns - kJitter_ns;  // enough history for "nothing came"
  }

  const DaemonConfig& config_;
  bool live_;
  std::deque<StatusSnapshot> history_;  // oldest first; the first is the all-zero start
  bool active_[kFaultCount] = {};
  std::array<bool, kMaxLidars> lidar_pps_locked_once_{};
  std::array<std::int8_t, kMaxLidars> lidar_model_said_{};  // -1 each (constructor): none said yet
  std::uint32_t silent_lidars_ = 0;                         // several LiDARs: those said to be silent
  // Each serial port's fault in a few words for the state ("NMEA text, no UBX"): GNSS, IMU.
  std::string serial_state_[2];
  StatusSnapshot minute_start_;  // the mixed LiDAR port's summary
  std::string state_ = "starting";
};

// The pose source's inputs in figures, for the status line: "gnss fix 3, h_acc 0.52 m, age
// 0.10 s; imu attitude age 0.01 s", "localization pose age 0.05 s", "pose fixed (pose.fixed)".
[[nodiscard]] std::string pose_inputs_text(const StatusSnapshot& s, const DaemonConfig& config);

}  // namespace trajroi::daemon
