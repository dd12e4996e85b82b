#include "trajroi/inputs/pacer.hpp"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>
#include <string>

#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/input_source.hpp"

namespace trajroi::inputs {

Pacer::Pacer(double rate) : rate_(rate) {
  if (!(rate >= 0.0) || !std::isfinite(rate))
    throw std::invalid_argument("replay rate must be >= 0, got " + std::to_string(rate));
}

std::int64_t Pacer::due_ns(std::int64_t recorded_ns) noexcept {
  if (!paced()) return host::monotonic_ns();
  if (!anchored_) {
    anchored_ = true;
    recorded0_ns_ = recorded_ns;
    wall0_ns_ = host::monotonic_ns();
  }
  return wall0_ns_ + static_cast<std::int64_t>(static_cast<double>(recorded_ns - recorded0_ns_) / rate_);
}

bool Pacer::sleep_until(std::int64_t deadline_ns, const std::atomic<bool>* stop) noexcept {
  constexpr std::int64_t kStopCheck_ns = 50'000'000;
  for (;;) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) return false;
    const std::int64_t now = host::monotonic_ns();
    if (now >= deadline_ns) return true;
    const std::int64_t until = stop != nullptr ? std::min(deadline_ns, now + kStopCheck_ns) : deadline_ns;
    const timespec ts{static_cast<time_t>(until / 1'000'000'000), static_cast<long>(until % 1'000'000'000)};
    (void)clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
  }
}

}  // namespace trajroi::inputs
