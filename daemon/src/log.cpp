#include "log.hpp"

#include <spdlog/sinks/stdout_sinks.h>

#include <cstdlib>

namespace trajroi::daemon::log {

void init(const std::string& level) {
  auto logger = spdlog::stderr_logger_mt("trajroid");
  // journald adds its own timestamps.
  if (std::getenv("JOURNAL_STREAM") != nullptr) {
    logger->set_pattern("%v");
  } else {
    logger->set_pattern("%Y-%m-%d %H:%M:%S.%e %^%-5l%$ %v");
  }
  spdlog::set_default_logger(logger);
  set_level(level);
}

void set_level(const std::string& level) {
  spdlog::set_level(spdlog::level::from_str(level));
}

bool RateLimited::allow(std::int64_t now_ns, std::uint64_t& suppressed) noexcept {
  std::int64_t next = next_ns_.load(std::memory_order_relaxed);
  if (now_ns < next || !next_ns_.compare_exchange_strong(next, now_ns + interval_ns_, std::memory_order_relaxed)) {
    held_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  suppressed = held_.exchange(0, std::memory_order_relaxed);
  return true;
}

}  // namespace trajroi::daemon::log
