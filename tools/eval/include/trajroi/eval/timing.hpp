#pragma once

#include <algorithm>
#include <chrono>
#include <limits>

namespace trajroi::eval {

// Minimum, maximum and mean wall time of repeated runs, in milliseconds.
struct TimingStats {
  double min_ms = 0.0;
  double max_ms = 0.0;
  double avg_ms = 0.0;
};

// Runs f() `reps` times (at least once) and times each run with the steady clock.
template <typename F>
TimingStats time_repeated(int reps, F&& f) {
  TimingStats t{std::numeric_limits<double>::infinity(), 0.0, 0.0};
  const int n = std::max(reps, 1);
  for (int r = 0; r < n; ++r) {
    const auto start = std::chrono::steady_clock::now();
    f();
    const auto stop = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(stop - start).count();
    t.min_ms = std::min(t.min_ms, ms);
    t.max_ms = std::max(t.max_ms, ms);
    t.avg_ms += ms;
  }
  t.avg_ms /= n;
  return t;
}

}  // namespace trajroi::eval
