#pragma once

// UTC for the wire formats: civil date and time → ns since 1970, and the ISO 8601 text the
// tools print. Proleptic Gregorian calendar through std::chrono; leap seconds are not
// counted (a 60th second runs into the next minute, as POSIX time does).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

namespace trajroi {

// Dates whose UTC time fits int64 nanoseconds (±292 years around 1970), with a day's margin.
[[nodiscard]] inline bool utc_representable(const std::chrono::year_month_day& date) noexcept {
  return date.ok() && date.year() >= std::chrono::year{1678} && date.year() <= std::chrono::year{2261};
}

// ns since 1970-01-01T00:00:00Z of `date` plus `second_of_day` (0 … 86 400) seconds. `date`
// must be utc_representable(); one that is not (a wire value such as UBX's year 65535) gives
// the earliest time, never an overflow.
[[nodiscard]] inline std::int64_t utc_ns_from_civil(const std::chrono::year_month_day& date,
                                                    std::int64_t second_of_day) noexcept {
  if (!utc_representable(date) || second_of_day < 0 || second_of_day > 86'400) {
    return std::numeric_limits<std::int64_t>::min();
  }
  const std::int64_t days = std::chrono::sys_days{date}.time_since_epoch().count();
  return (days * 86'400 + second_of_day) * 1'000'000'000;
}

// "2017-07-19T08:50:01.000Z": UTC rounded to the nearest millisecond.
[[nodiscard]] inline std::string format_utc_ms(std::int64_t utc_ns) {
  namespace c = std::chrono;
  const c::sys_time<c::milliseconds> t = c::round<c::milliseconds>(c::sys_time<c::nanoseconds>{c::nanoseconds{utc_ns}});
  const auto day = c::floor<c::days>(t);
  const c::year_month_day ymd{day};
  const c::hh_mm_ss hms{t - day};
  char text[48];
  std::snprintf(text, sizeof text, "%04d-%02u-%02uT%02ld:%02ld:%02ld.%03ldZ", int{ymd.year()}, unsigned{ymd.month()},
                unsigned{ymd.day()}, static_cast<long>(hms.hours().count()), static_cast<long>(hms.minutes().count()),
                static_cast<long>(hms.seconds().count()), static_cast<long>(hms.subseconds().count()));
  return text;
}

}  // namespace trajroi
