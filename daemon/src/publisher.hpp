#pragma once

// The publisher thread: sweeps and status snapshots from the processing thread out through the
// Outlet (LCM: points, pose, roi, status), trajectory messages and SIGHUP reloads in. Its jobs
// each have a type of their own: MessageSender (encode and send), TrajectoryIntake (trajectory
// messages and reloads), LatencyBook (latency, late sweeps), HealthMonitor (faults and
// systemd's STATUS=), MinuteLine (the minute's line); this class runs the loop and wires them.
//
// Live, the processing thread may publish the sweep it just finished itself (publish_here,
// realtime.publish_from_processing): that state then has one owner at a time, whichever
// thread holds the publishing lock; the publisher thread holds it while it works and lets go
// while it waits.
#include <cstdint>
#include <mutex>

#include "corrections_watch.hpp"
#include "health.hpp"
#include "latency_book.hpp"
#include "log.hpp"
#include "message_sender.hpp"
#include "minute_line.hpp"
#include "outlet.hpp"
#include "pipeline.hpp"
#include "reload.hpp"
#include "status.hpp"
#include "trajectory_intake.hpp"
#include "trajroi/daemon/latency_histogram.hpp"
#include "trajroi/status_t.hpp"

namespace trajroi::daemon {

class Publisher final : public SweepHandOver {
 public:
  // `replay`: said in the status message. `reloader` may be null (no SIGHUP reloads).
  // `trajectory`: the one active at start (published on lcm.channels.active_trajectory).
  Publisher(Pipeline& pipeline, Outlet& outlet, Reloader* reloader, bool replay,
            const pipeline::ActiveTrajectory& trajectory);
  void run();
  // The processing thread: the sweeps waiting go out on it if the publisher thread is idle.
  [[nodiscard]] bool publish_here() override;

  // After run(): the last status and the whole run's latency, for the summary.
  [[nodiscard]] const StatusSnapshot& last_status() const noexcept { return last_status_; }
  [[nodiscard]] const LatencyHistogram& latency() const noexcept { return latency_.all(); }

 private:
  void publish_sweep(const pipeline::Sweep& s);
  // Every sweep in the ring, oldest first.
  void publish_pending_sweeps();
  void publish_status(const StatusSnapshot& s);
  // " | recording into DIR", or "" when not recording.
  [[nodiscard]] std::string recording_text() const;
  // ", RTK fixed | corrections: streaming from …, age 0.4 s, 530 B/s" ("" without either).
  [[nodiscard]] std::string rtk_text(const trajroi::status_t& m) const;

  // Held by the thread that publishes (everything below is its); the publisher thread's
  // waits are outside it.
  std::mutex publishing_;
  Pipeline& pipeline_;
  Outlet& outlet_;
  bool replay_;
  const DaemonConfig& config_;
  std::int64_t start_steady_ns_;
  MessageSender sender_;
  TrajectoryIntake trajectories_;
  LatencyBook latency_;
  HealthMonitor health_;
  CorrectionsWatch corrections_;
  MinuteLine minute_;
  StatusSnapshot last_status_;
  log::ReasonLimiter sweep_warnings_;  // withheld sweeps, by reason
};

}  // namespace trajroi::daemon
