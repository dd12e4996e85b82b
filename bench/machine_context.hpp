#pragma once

// Every benchmark program's context (printed before its figures) names the machine: the CPU
// model, the cores it may use and the SIMD scans the CPU has. register_core_clock() adds a
// benchmark that measures the core's clock while the others run.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "trajroi/roi/cpu.hpp"

namespace trajroi::bench {

inline const int kMachineContext = (benchmark::AddCustomContext("machine", roi::describe_machine()), 0);

// Adds the fastest and the slowest repetition to a benchmark's aggregates (`_min`, `_max`), so
// that a script can print a figure's range over an interleaved run.
inline benchmark::internal::Benchmark* with_range(benchmark::internal::Benchmark* b) {
  return b->ComputeStatistics("min", [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); })
      ->ComputeStatistics("max", [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); });
}

#if defined(__x86_64__) || defined(__i386__)
// A chain of kClockAdds dependent integer additions: one per cycle on every x86 core, so one
// iteration takes kClockAdds / clock. A shared host can slow a guest's core, often, for tenths
// of a second: a figure taken in such a spell is slower for a compute-bound loop and hardly for
// a memory-bound one (a memcpy), which a ratio of the two does not cancel.
inline constexpr std::uint64_t kClockAdds = 10'000'000;
inline void core_clock(benchmark::State& state) {
  std::uint64_t x = 0;
  for (auto _ : state) {
    for (std::uint64_t i = 0; i < kClockAdds; ++i)
      asm volatile("add $1, %0" : "+r"(x));
  }
  benchmark::DoNotOptimize(x);
  state.counters["adds"] = benchmark::Counter(static_cast<double>(kClockAdds) * static_cast<double>(state.iterations()),
                                              benchmark::Counter::kIsRate, benchmark::Counter::kIs1000);
}

// Registers `probe/clock` (milliseconds per kClockAdds additions) with its range.
inline void register_core_clock() {
  with_range(benchmark::RegisterBenchmark("probe/clock", core_clock))->Unit(benchmark::kMillisecond);
}
#else
inline void register_core_clock() {}
#endif

}  // namespace trajroi::bench
