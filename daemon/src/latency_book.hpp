#pragma once

// The publisher's latency bookkeeping: each sweep's time from its last packet to its LCM
// publication and where that time went, the figures of the current status window and minute,
// the whole run's histogram, and the late sweeps described in the log.
#include <cstdint>
#include <string>
#include <vector>

#include "log.hpp"
#include "trajroi/daemon/latency_histogram.hpp"

namespace trajroi::daemon {

// A sweep this late from its last packet to its LCM publication is described in the log.
inline constexpr double kLateSweep_ms = 5.0;

// Where a sweep's time went, from its last packet's arrival to its points sent.
struct SweepTiming {
  std::uint64_t index = 0;
  double total_ms = -1.0;           // < 0: no sweep yet
  double merge_wait_ms = 0.0;       // several LiDARs: the merge waiting for sensors that did not come
  double processing_wait_ms = 0.0;  // waiting for the processing thread to take the closing packet
  double closing_ms = 0.0;          // the closing packet and the hand-over
  double publisher_wait_ms = 0.0;   // waiting in the ring for the publisher
  double encoding_ms = 0.0, sending_ms = 0.0;
  // "12.30 ms from its last packet to LCM (waiting for the processing thread …, sending … ms)";
  // a merged sweep that waited for other LiDARs says that first.
  [[nodiscard]] std::string describe() const;
};

class LatencyBook {
 public:
  // `describe_late`: late sweeps are described (not in an as-fast replay, whose queue is the
  // design), at most once per `warning_interval_s`.
  LatencyBook(double warning_interval_s, bool describe_late);

  // A whole sweep sent at `sent_ns` (steady clock).
  void add(const SweepTiming& t, std::int64_t sent_ns);
  // The processing time of a sweep (published or withheld).
  void add_processing(double ms);

  // The status window's percentiles (q in [0, 1]; 0 without samples), until end_window().
  [[nodiscard]] double window_latency_ms(double q);
  [[nodiscard]] double window_processing_ms(double q);
  void end_window();
  // The minute's percentiles and its slowest sweep, until end_minute().
  [[nodiscard]] double minute_latency_ms(double q);
  [[nodiscard]] const SweepTiming& slowest_in_minute() const noexcept { return slowest_in_minute_; }
  void end_minute();

  [[nodiscard]] const LatencyHistogram& all() const noexcept { return all_; }
  [[nodiscard]] std::uint64_t late_sweeps() const noexcept { return late_sweeps_; }
  [[nodiscard]] bool describes_late() const noexcept { return describe_late_; }

 private:
  bool describe_late_;
  std::vector<double> window_ms_, processing_window_ms_, minute_ms_;  // reserved: no allocation
  LatencyHistogram all_;
  log::RateLimited late_limit_;
  std::uint64_t late_sweeps_ = 0;
  // The current minute's slowest sweep, named with the minute's line when late: one per
  // minute, whatever the warning interval let through.
  SweepTiming slowest_in_minute_;
};

}  // namespace trajroi::daemon
