#include "log.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "trajroi/host/clock.hpp"

namespace trajroi::daemon::log {
namespace {

// Whether stderr is the journal's stream: JOURNAL_STREAM names its device and inode
// (sd-daemon(3)); a child whose stderr was redirected inherits the variable but not the stream.
bool stderr_is_journal() {
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (stream == nullptr) return false;
  std::uintmax_t device = 0, inode = 0;
  if (std::sscanf(stream, "%" SCNuMAX ":%" SCNuMAX, &device, &inode) != 2) return false;
  struct stat s {};
  return fstat(STDERR_FILENO, &s) == 0 && s.st_dev == device && s.st_ino == inode;
}

// The syslog priority prefix journald reads off each stderr line ("<4>" = warning), so
// `journalctl -p warning` finds trajroid's warnings and errors.
constexpr const char* kPriority[] = {"<7>", "<7>", "<6>", "<4>", "<3>", "<2>", "<6>"};  // trace … critical, off

class SyslogPriority final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& message, const std::tm&, spdlog::memory_buf_t& out) override {
    const char* prefix = kPriority[static_cast<int>(message.level)];
    out.append(prefix, prefix + 3);
  }
  [[nodiscard]] std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<SyslogPriority>();
  }
};

}  // namespace

void init(const std::string& level) {
  auto logger = spdlog::stderr_logger_mt("trajroid");
  if (stderr_is_journal()) {
    // journald adds its own timestamps; the level travels as the line's priority.
    auto formatter = std::make_unique<spdlog::pattern_formatter>();
    formatter->add_flag<SyslogPriority>('*').set_pattern("%*%v");
    logger->set_formatter(std::move(formatter));
  } else {
    logger->set_pattern("%Y-%m-%d %H:%M:%S.%e %^%-5l%$ %v");
  }
  spdlog::set_default_logger(logger);
  set_level(level);
}

const char* journal_prefix(spdlog::level::level_enum level) {
  static const bool journal = stderr_is_journal();
  return journal ? kPriority[static_cast<int>(level)] : "";
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

void warn_limited(RateLimited& limit, const std::string& message) {
  std::uint64_t suppressed = 0;
  if (!limit.allow(host::monotonic_ns(), suppressed)) return;
  if (suppressed > 0) {
    warn("{} ({} similar warnings suppressed)", message, suppressed);
  } else {
    warn("{}", message);
  }
}

void ReasonLimiter::warn(std::uint32_t reason, const std::string& message, std::int64_t now_ns) {
  Reason& r = reasons_[reason];
  const std::int64_t wall = host::realtime_ns();
  if (now_ns < r.next_ns) {
    if (r.held++ == 0) r.first_held_wall_ns = wall;
    r.last_held_wall_ns = wall;
    r.last_message = message;
    return;
  }
  if (r.held > 0) {
    log::warn("{} (and {} like it from {} to {})", message, r.held, time_of_day(r.first_held_wall_ns),
              time_of_day(r.last_held_wall_ns));
  } else {
    log::warn("{}", message);
  }
  r.held = 0;
  r.next_ns = now_ns + interval_ns_;
}

void ReasonLimiter::flush(std::int64_t now_ns) {
  for (auto& [reason, r] : reasons_) {
    if (r.held == 0 || now_ns < r.next_ns) continue;
    log::warn("{} ({} time{} from {} to {})", r.last_message, r.held, r.held == 1 ? "" : "s",
              time_of_day(r.first_held_wall_ns), time_of_day(r.last_held_wall_ns));
    r.held = 0;
    r.next_ns = now_ns + interval_ns_;
  }
}

std::string time_of_day(std::int64_t realtime_ns) {
  const std::time_t seconds = static_cast<std::time_t>(realtime_ns / 1'000'000'000);
  std::tm t{};
  localtime_r(&seconds, &t);
  char text[32];
  std::snprintf(text, sizeof text, "%02d:%02d:%02d.%03d", t.tm_hour, t.tm_min, t.tm_sec,
                static_cast<int>(realtime_ns % 1'000'000'000 / 1'000'000));
  return text;
}

}  // namespace trajroi::daemon::log
