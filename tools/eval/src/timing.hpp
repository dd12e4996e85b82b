#pragma once

// Wall-clock timing of the evaluations' steps (the paper's processing-time tables).
#include <algorithm>
#include <chrono>
#include <cstddef>

#include "trajroi/eval/scenario_eval.hpp"

namespace trajroi::eval {

inline double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

// Adds one sample to running min / max / mean statistics over `n` samples so far.
inline void add_sample(TimingStats& t, std::size_t& n, double ms) {
  if (n == 0) t = {ms, ms, 0.0};
  t.min_ms = std::min(t.min_ms, ms);
  t.max_ms = std::max(t.max_ms, ms);
  t.avg_ms += (ms - t.avg_ms) / static_cast<double>(++n);
}

}  // namespace trajroi::eval
