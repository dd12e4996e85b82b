#pragma once

// trajroid's one logging facade over spdlog: stderr (journald under systemd), the level from
// the configuration, and RateLimited for anything that could fire per packet.
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstdint>
#include <string>

namespace trajroi::daemon::log {

// Sets up the stderr logger. When stderr is the journal (JOURNAL_STREAM names it) lines carry
// no timestamp, journald adds its own, and start with their syslog priority ("<4>" warning).
void init(const std::string& level);
void set_level(const std::string& level);

// For lines written to stderr before (or without) the logger: "<3>" for an error when stderr
// is the journal, else "" (a terminal or a file gets the plain line).
[[nodiscard]] const char* journal_prefix(spdlog::level::level_enum level);

using spdlog::critical;
using spdlog::debug;
using spdlog::error;
using spdlog::info;
using spdlog::warn;

// At most one message per interval; the ones held back are counted and reported with the
// next one let through. Thread-safe and lock-free.
class RateLimited {
 public:
  explicit RateLimited(double interval_s) : interval_ns_(static_cast<std::int64_t>(interval_s * 1e9)) {}
  // True when a message may go out now; `suppressed` is then how many were held back since.
  bool allow(std::int64_t now_ns, std::uint64_t& suppressed) noexcept;

 private:
  std::int64_t interval_ns_;
  std::atomic<std::int64_t> next_ns_{0};
  std::atomic<std::uint64_t> held_{0};
};

// A warning through `limit`: at most one per its interval, with the count held back since.
void warn_limited(RateLimited& limit, const std::string& message);

}  // namespace trajroi::daemon::log
