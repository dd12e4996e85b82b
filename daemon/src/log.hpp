#pragma once

// trajroid's one logging facade over spdlog: stderr (journald under systemd), the level from
// the configuration, and RateLimited for anything that could fire per packet.
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstdint>
#include <map>
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

// Warnings by reason: a reason not said within the interval is said at once, however many
// lines of other reasons are being held back; its repeats within the interval are held and
// summarised once the interval has passed: with the next one ("… (and 52 like it from
// 20:01:02.100 to 20:01:06.900)"), or by flush() (called once a second) when none comes (the
// last one held, "… (52 times from … to …)"). So a
// new cause is in the log as it appears and a lasting one once per interval. One thread's.
class ReasonLimiter {
 public:
  explicit ReasonLimiter(double interval_s) : interval_ns_(static_cast<std::int64_t>(interval_s * 1e9)) {}
  void warn(std::uint32_t reason, const std::string& message, std::int64_t now_ns);
  // Says the summaries whose interval has passed.
  void flush(std::int64_t now_ns);

 private:
  struct Reason {
    std::int64_t next_ns = 0;  // said again from then on
    std::uint64_t held = 0;
    std::int64_t first_held_wall_ns = 0, last_held_wall_ns = 0;
    std::string last_message;
  };
  std::int64_t interval_ns_;
  std::map<std::uint32_t, Reason> reasons_;
};

// A CLOCK_REALTIME time as the log's clock time of day, "20:01:02.100" (local time).
[[nodiscard]] std::string time_of_day(std::int64_t realtime_ns);

}  // namespace trajroi::daemon::log
