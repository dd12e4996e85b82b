#pragma once

// The host's clocks, in ns: one definition for the whole project. CLOCK_MONOTONIC is the time
// base of every receive stamp, latency, deadline and replay pace; CLOCK_REALTIME only turns a
// monotonic time into UTC (live) and stamps logs.
#include <cstdint>

namespace trajroi::host {

[[nodiscard]] std::int64_t monotonic_ns() noexcept;
[[nodiscard]] std::int64_t realtime_ns() noexcept;
// The calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID).
[[nodiscard]] std::int64_t thread_cpu_ns() noexcept;

}  // namespace trajroi::host
