#pragma once

// The one pacer: plays recorded receive times back against CLOCK_MONOTONIC at a rate (0: as
// fast as possible, 1: real time, N: N × real time). The first item paced anchors the clock.
#include <atomic>
#include <cstdint>

namespace trajroi::inputs {

class Pacer {
 public:
  // Throws std::invalid_argument for a negative or non-finite rate.
  explicit Pacer(double rate);
  [[nodiscard]] bool paced() const noexcept { return rate_ > 0.0; }
  [[nodiscard]] double rate() const noexcept { return rate_; }
  // The CLOCK_MONOTONIC time an item recorded at `recorded_ns` is due (now when not paced).
  [[nodiscard]] std::int64_t due_ns(std::int64_t recorded_ns) noexcept;
  // Sleeps until `deadline_ns` (CLOCK_MONOTONIC), waking at least every 50 ms to look at
  // `stop` (may be null). False when stopped first.
  static bool sleep_until(std::int64_t deadline_ns, const std::atomic<bool>* stop = nullptr) noexcept;

 private:
  double rate_;
  bool anchored_ = false;
  std::int64_t recorded0_ns_ = 0, wall0_ns_ = 0;
};

}  // namespace trajroi::inputs
