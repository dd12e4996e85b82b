#include "minute_line.hpp"

#include <spdlog/fmt/fmt.h>
#include <unistd.h>

#include <cstdio>
#include <string>

namespace trajroi::daemon {
namespace {

double rss_mib() {
  long pages = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    long size = 0;
    if (std::fscanf(f, "%ld %ld", &size, &pages) != 2) pages = 0;
    std::fclose(f);
  }
  return static_cast<double>(pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

}  // namespace

void MinuteLine::on_status(const StatusSnapshot& s, LatencyBook& latency) {
  if (minute_start_.steady_ns == 0) minute_start_ = s;
  if (s.steady_ns - minute_start_.steady_ns >= 60'000'000'000 || s.final) write(s, latency);
}

void MinuteLine::write(const StatusSnapshot& s, LatencyBook& latency) {
  // A late maximum says where its time went (an as-fast replay's queue is not lateness).
  const SweepTiming& slowest_sweep = latency.slowest_in_minute();
  const std::string slowest =
      slowest_sweep.total_ms > kLateSweep_ms && latency.describes_late()
          ? fmt::format(" | slowest: sweep {} {}", slowest_sweep.index, slowest_sweep.describe())
          : std::string();
  log::info(
      "minute: {:.0f} s | sweeps {} published {} | latency p50 {:.2f} p99 {:.2f} max {:.2f} ms | ring drops {} | "
      "kernel drops {} | lost packets {} | RSS {:.1f} MiB{}",
      static_cast<double>(s.steady_ns - minute_start_.steady_ns) * 1e-9,
      s.processor.sweeps - minute_start_.processor.sweeps,
      s.processor.sweeps_filtered - minute_start_.processor.sweeps_filtered, latency.minute_latency_ms(0.50),
      latency.minute_latency_ms(0.99), latency.minute_latency_ms(1.0), s.ring_drops() - minute_start_.ring_drops(),
      s[Counter::kLidarKernelDrops] - minute_start_[Counter::kLidarKernelDrops],
      s.lost_packets - minute_start_.lost_packets, rss_mib(), slowest);
  latency.end_minute();
  minute_start_ = s;
}

}  // namespace trajroi::daemon
