#pragma once

// The publisher thread: sweeps and status snapshots from the processing thread out through the
// Outlet (LCM: points, pose, roi, status), trajectory messages in (checked, then offered to the
// processing thread), SIGHUP reloads offered likewise, latency percentiles per status window
// and per minute, and the run's summary figures.
#include <cstdint>
#include <string>
#include <vector>

#include "health.hpp"
#include "log.hpp"
#include "outlet.hpp"
#include "pipeline.hpp"
#include "reload.hpp"
#include "status.hpp"
#include "trajroi/daemon/latency_histogram.hpp"
#include "trajroi/daemon/messages.hpp"
#include "trajroi/pose/geodetic.hpp"

namespace trajroi::daemon {

// A sweep this late from its last packet to its LCM publication is described in the log.
inline constexpr double kLateSweep_ms = 5.0;

class Publisher {
 public:
  // `replay`: said in the status message. `reloader` may be null (no SIGHUP reloads).
  Publisher(Pipeline& pipeline, Outlet& outlet, Reloader* reloader, bool replay);
  void run();

  // After run(): the last status and the whole run's latency, for the summary.
  [[nodiscard]] const StatusSnapshot& last_status() const noexcept { return last_status_; }
  [[nodiscard]] const LatencyHistogram& latency() const noexcept { return latency_all_; }

 private:
  void on_trajectory_message(std::span<const std::uint8_t> bytes, const std::string& channel);
  void offer(std::unique_ptr<pipeline::ActiveTrajectory> trajectory);
  void publish_sweep(const pipeline::Sweep& s);
  // Every sweep in the ring, oldest first.
  void publish_pending_sweeps();
  // Where a sweep's time went, from its last packet's arrival to its points sent.
  struct SweepTiming {
    std::uint64_t index = 0;
    double total_ms = -1.0;           // < 0: no sweep yet
    double processing_wait_ms = 0.0;  // waiting for the processing thread to take the closing packet
    double closing_ms = 0.0;          // the closing packet and the hand-over
    double publisher_wait_ms = 0.0;   // waiting in the ring for the publisher
    double encoding_ms = 0.0, sending_ms = 0.0;
    // "12.30 ms from its last packet to LCM (waiting for the processing thread …, sending … ms)"
    [[nodiscard]] std::string describe() const;
  };
  // A sweep later than kLateSweep_ms from its last packet to LCM: where the time went, said at
  // most once per logging.warning_interval_s (not at --rate max, where the queue is the design).
  void report_late(const SweepTiming& t, std::int64_t sent_ns);
  void publish_status(const StatusSnapshot& s);
  void log_minute(const StatusSnapshot& s);
  void take_reloads();
  // At most one warning per logging.warning_interval_s per limiter, with the count suppressed.
  static void warn_rate_limited(log::RateLimited& limit, const std::string& message);
  template <typename Message>
  void send(const std::string& channel, const Message& m);

  Pipeline& pipeline_;
  Outlet& outlet_;
  Reloader* reloader_;
  bool replay_;
  const DaemonConfig& config_;
  pose::GlobalFrame frame_;
  std::vector<std::uint8_t> encoded_;
  std::vector<std::uint8_t> points_encoded_;
  trajroi::points_t points_;
  trajroi::pose_t pose_;
  trajroi::roi_t roi_;
  std::array<std::uint64_t, kTrajectoryRejectCount> trajectory_rejects_{};
  std::uint64_t trajectories_accepted_ = 0, trajectory_reloads_ = 0, trajectory_reload_errors_ = 0;
  std::vector<double> latency_window_ms_, processing_window_ms_, latency_minute_ms_;
  LatencyHistogram latency_all_;
  StatusSnapshot minute_start_;  // the status at the start of the current minute
  StatusSnapshot last_status_;
  std::int64_t start_steady_ns_;
  HealthMonitor health_;
  log::RateLimited sweep_warn_limit_;       // withheld sweeps
  log::RateLimited trajectory_warn_limit_;  // rejected trajectory messages: never hidden by the above
  log::RateLimited late_limit_;             // late sweeps
  std::uint64_t late_sweeps_ = 0;
  // The current minute's slowest sweep, named with the minute's line when late: one per
  // minute, whatever the warning interval let through.
  SweepTiming slowest_in_minute_;
};

}  // namespace trajroi::daemon
