#include "latency_book.hpp"

#include <spdlog/fmt/fmt.h>

#include <algorithm>

namespace trajroi::daemon {
namespace {

double percentile(std::vector<double>& samples, double q) {
  if (samples.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(
      std::min(q * static_cast<double>(samples.size()), static_cast<double>(samples.size() - 1)));
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(k), samples.end());
  return samples[k];
}

void add_bounded(std::vector<double>& samples, double ms) {
  if (samples.size() < samples.capacity()) samples.push_back(ms);
}

}  // namespace

std::string SweepTiming::describe() const {
  const std::string merge =
      merge_wait_ms > 0.0
          ? fmt::format("waiting for the other LiDARs' sweeps {:.2f} (lidar_merge.max_wait_s), ", merge_wait_ms)
          : std::string();
  return fmt::format(
      "{:.2f} ms from its last packet to LCM ({}waiting for the processing thread {:.2f}, the closing packet and "
      "hand-over {:.2f}, waiting for the publisher {:.2f}, encoding {:.2f}, sending {:.2f} ms)",
      total_ms, merge, processing_wait_ms, closing_ms, publisher_wait_ms, encoding_ms, sending_ms);
}

LatencyBook::LatencyBook(double warning_interval_s, bool describe_late)
    : describe_late_(describe_late), late_limit_(warning_interval_s) {
  window_ms_.reserve(4096);
  processing_window_ms_.reserve(4096);
  minute_ms_.reserve(1U << 16);
}

void LatencyBook::add(const SweepTiming& t, std::int64_t sent_ns) {
  if (t.total_ms > slowest_in_minute_.total_ms) slowest_in_minute_ = t;
  if (t.total_ms > kLateSweep_ms && describe_late_) {
    ++late_sweeps_;
    std::uint64_t suppressed = 0;
    if (late_limit_.allow(sent_ns, suppressed)) {
      log::info("sweep {} late: {}; {} late sweeps (over {:.0f} ms) so far{}", t.index, t.describe(), late_sweeps_,
                kLateSweep_ms,
                suppressed > 0 ? " (" + std::to_string(suppressed) + " late sweeps not described)" : std::string());
    }
  }
  add_bounded(window_ms_, t.total_ms);
  add_bounded(minute_ms_, t.total_ms);
  all_.add(t.total_ms);
}

void LatencyBook::add_processing(double ms) {
  add_bounded(processing_window_ms_, ms);
}

double LatencyBook::window_latency_ms(double q) {
  return percentile(window_ms_, q);
}

double LatencyBook::window_processing_ms(double q) {
  return percentile(processing_window_ms_, q);
}

void LatencyBook::end_window() {
  window_ms_.clear();
  processing_window_ms_.clear();
}

double LatencyBook::minute_latency_ms(double q) {
  return percentile(minute_ms_, q);
}

void LatencyBook::end_minute() {
  minute_ms_.clear();
  slowest_in_minute_ = {};
}

}  // namespace trajroi::daemon
