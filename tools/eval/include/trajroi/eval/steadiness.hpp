#pragma once

// How steadily a machine gives a thread its CPU. A fixed piece of arithmetic (no memory, no
// system calls) is timed again and again; where it took much longer than at the machine's
// full speed, the thread was not running for part of it. When the timing thread runs above
// every other thread of the machine (SCHED_FIFO), nothing on the machine caused that: it is
// the machine's own slow spell (a hypervisor taking the CPU away in slices, firmware, …),
// and a real-time figure measured then measures it too. cyclictest's wake-up delay misses
// spells made of many short gaps; a thread that needs a few milliseconds of CPU does not.
#include <cstddef>
#include <span>
#include <vector>

namespace trajroi::eval {

struct PieceTiming {
  double start_s = 0.0;      // since the run's start
  double duration_us = 0.0;  // wall time the piece took
};

struct SlowSpell {
  double start_s = 0.0;  // the first slow piece's start
  double end_s = 0.0;    // the last slow piece's end
  double worst_factor = 0.0;
  std::size_t pieces = 0;  // slow pieces in the spell
};

struct Steadiness {
  std::size_t pieces = 0;
  double full_speed_us = 0.0;  // the 10th percentile of the pieces' durations
  double median_us = 0.0;
  std::vector<SlowSpell> spells;

  [[nodiscard]] double longest_ms() const noexcept;
  [[nodiscard]] double worst_factor() const noexcept;  // 0 without a spell
  [[nodiscard]] double slow_ms() const noexcept;       // the spells' total length
};

// Pieces slower than `factor` × full speed are slow; slow pieces less than `merge_s` apart
// (start to end) make one spell. Full speed is the 10th percentile of the pieces' durations:
// robust to a few pieces sped up or slowed down, and still the machine's speed when it was
// slow half of the time.
[[nodiscard]] Steadiness find_slow_spells(std::span<const PieceTiming> pieces, double factor = 2.0,
                                          double merge_s = 0.02);

}  // namespace trajroi::eval
