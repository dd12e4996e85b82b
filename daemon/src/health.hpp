#pragma once

// Every fault named: once a second the publisher hands each status snapshot here; a fault
// seen over the last few seconds (the counters' change since then) is said in one log line
// with its figures when it starts — within 5 s of the start or of the fault — and once more
// when it ends. The same look gives systemd's STATUS= its words ("waiting for LiDAR data on
// UDP port 2368", "no valid pose: no GNSS fix yet", "publishing 10.0 sweeps/s").
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
  // The state in words, for STATUS=.
  [[nodiscard]] const std::string& state() const noexcept { return state_; }

  // A fault is judged over at least this much history (the lines come within 5 s).
  static constexpr std::int64_t kWindow_ns = 3'000'000'000;

 private:
  enum Fault : std::uint8_t {
    kLidarSilent,
    kLidarForeignOnly,
    kGnssSilent,
    kGnssNoFrames,
    kGnssNoPvt,
    kImuSilent,
    kImuNoFrames,
    kImuNoAttitude,
    kTrajectoryFar,
    kClockOffset,
    kFaultCount
  };
  // Raises or clears `fault`: true → the warning (once, as it starts); false → the info line
  // (once, as it ends) when `ended` is given.
  void set(Fault fault, bool active, std::string warning, std::string ended, std::vector<HealthLine>& out);

  const DaemonConfig& config_;
  bool live_;
  std::deque<StatusSnapshot> history_;  // oldest first; the first is the all-zero start
  bool active_[kFaultCount] = {};
  std::string state_ = "starting";
};

}  // namespace trajroi::daemon
