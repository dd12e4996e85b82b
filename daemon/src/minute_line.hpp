#pragma once

// Once a minute (and at the final status), one log line for the journal and the soak tests:
// what the last minute did (sweeps, latency percentiles and maximum, drops, lost packets) and
// the process's resident memory; a late maximum says where its time went.
#include "latency_book.hpp"
#include "status.hpp"

namespace trajroi::daemon {

class MinuteLine {
 public:
  // At every status snapshot; logs when a minute has passed since the last line, or at the end.
  void on_status(const StatusSnapshot& s, LatencyBook& latency);

 private:
  void write(const StatusSnapshot& s, LatencyBook& latency);
  StatusSnapshot minute_start_;  // the status at the start of the current minute
};

}  // namespace trajroi::daemon
