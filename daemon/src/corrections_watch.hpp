#pragma once

// The RTK state in the status and the log, once a second (publisher thread): the carrier
// solution's changes named ("RTK fixed", "RTK float", "RTK lost: standalone fix"), the
// corrections' age against gnss.max_correction_age_s ("corrections: none written into the
// receiver for 7.0 s (more than …): <the source's state>", and when they flow again), and the
// figures for status_t: the source's state, the age, bytes/s, frames by RTCM message number,
// CRC failures, bytes that were not RTCM3, frames written and lost.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "health.hpp"
#include "status.hpp"

namespace trajroi::daemon {

class CorrectionsLink;

struct CorrectionsFigures {
  std::string text;  // "" when none is configured
  double age_s = 0.0;
  double bytes_per_s = 0.0;
};

class CorrectionsWatch {
 public:
  // `link`: null when no corrections are configured (the RTK solution is still watched).
  CorrectionsWatch(const DaemonConfig& config, const CorrectionsLink* link, bool live);

  using AddCounter = std::function<void(std::string, std::uint64_t)>;
  // The figures at `s` (now_ns: CLOCK_MONOTONIC), its counters through `add`, and the lines to log.
  CorrectionsFigures update(const StatusSnapshot& s, std::int64_t now_ns, const AddCounter& add,
                            std::vector<HealthLine>& lines);

 private:
  const DaemonConfig& config_;
  const CorrectionsLink* link_;
  bool live_;
  std::int8_t rtk_ = -1;
  bool old_ = false;
  std::uint64_t bytes_ = 0;
  std::int64_t bytes_at_ns_ = 0;
  std::int64_t started_ns_ = 0;
};

}  // namespace trajroi::daemon
