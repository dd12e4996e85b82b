#pragma once

// Latencies over a whole run in fixed memory (a daemon runs for weeks): 10 µs bins up to
// 100 ms, anything longer in one bin above, and the maximum. Allocated and touched once.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace trajroi::daemon {

class LatencyHistogram {
 public:
  static constexpr double kBin_ms = 0.01;
  static constexpr std::size_t kBins = 10'000;  // up to 100 ms

  LatencyHistogram() : counts_(kBins + 1, 0) {}

  void add(double ms) noexcept {
    const double bin = std::floor(std::max(ms, 0.0) / kBin_ms);
    ++counts_[bin >= static_cast<double>(kBins) ? kBins : static_cast<std::size_t>(bin)];
    ++total_;
    max_ms_ = std::max(max_ms_, ms);
  }
  [[nodiscard]] std::uint64_t count() const noexcept { return total_; }
  // The q-quantile as the upper edge of its bin (never above the largest value seen); 0 when
  // empty.
  [[nodiscard]] double quantile(double q) const noexcept {
    if (total_ == 0) return 0.0;
    const auto rank = static_cast<std::uint64_t>(
        std::clamp(std::ceil(q * static_cast<double>(total_)), 1.0, static_cast<double>(total_)));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
      seen += counts_[i];
      if (seen >= rank) return std::min(static_cast<double>(i + 1) * kBin_ms, max_ms_);
    }
    return max_ms_;
  }

 private:
  std::vector<std::uint64_t> counts_;
  std::uint64_t total_ = 0;
  double max_ms_ = 0.0;
};

}  // namespace trajroi::daemon
