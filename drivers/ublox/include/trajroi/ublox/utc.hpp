#pragma once

// Civil UTC time ↔ nanoseconds since 1970, and the ISO 8601 form the dumps print.
#include <cstdint>
#include <string>

namespace trajroi::ublox {

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
[[nodiscard]] std::int64_t days_from_civil(int year, unsigned month, unsigned day) noexcept;

// "2017-07-19T08:50:01.000Z": UTC rounded to the nearest millisecond.
[[nodiscard]] std::string format_utc_ms(std::int64_t utc_ns);

}  // namespace trajroi::ublox
