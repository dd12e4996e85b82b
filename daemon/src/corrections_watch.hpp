#pragma once

// The RTK state in the status and the log, once a second (publisher thread): the carrier
// solution's changes named ("RTK fixed", "RTK float", "RTK lost: standalone fix"), the
// corrections' age against gnss.max_correction_age_s ("corrections: none written into the
// receiver for 7.0 s (more than …): <the source's state>", and when they flow again), and the
// figures for status_t: the source's state, the age, bytes/s, frames by RTCM message number,
// CRC failures, bytes that were not RTCM3, frames written and lost. A stream that brings bytes
// but no RTCM3 frame for 3 s is named, and CRC failures at most once a minute.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "health.hpp"
#include "status.hpp"

namespace trajroi::daemon {

class CorrectionsLink;
struct CorrectionsStats;

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
  void not_rtcm3(const CorrectionsStats& c, std::int64_t now_ns, std::vector<HealthLine>& lines);
  const DaemonConfig& config_;
  const CorrectionsLink* link_;
  bool live_;
  std::int8_t rtk_ = -1;
  bool old_ = false;
  std::uint64_t bytes_ = 0;
  std::int64_t bytes_at_ns_ = 0;
  std::int64_t started_ns_ = 0;
  // Bytes without frames: seconds in a row, and whether it was said.
  std::uint64_t frames_ = 0, other_bytes_ = 0, frameless_bytes_ = 0;
  int frameless_s_ = 0;
  bool frameless_said_ = false;
  std::int64_t crc_said_ns_ = 0;
  std::uint64_t crc_said_ = 0;
};

}  // namespace trajroi::daemon
