#include "trajroi/corrections/gga.hpp"

#include <cmath>
#include <cstdio>

namespace trajroi::corrections {

std::string gga_sentence(const GgaFix& fix) {
  const std::int64_t day_ns = 86'400'000'000'000;
  const std::int64_t of_day = ((fix.utc_ns % day_ns) + day_ns) % day_ns;
  const auto centiseconds = of_day / 10'000'000;
  const auto hours = centiseconds / 360'000, minutes = centiseconds / 6'000 % 60;
  const double seconds = static_cast<double>(centiseconds % 6'000) / 100.0;
  const auto angle = [](double deg, int degree_digits, char positive, char negative) {
    const double a = std::abs(deg);
    auto whole = static_cast<int>(a);
    double minutes_of = (a - whole) * 60.0;
    if (minutes_of >= 59.99999995) {  // rounds up to 60.0000000 at 7 decimals
      minutes_of = 0.0;
      ++whole;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%0*d%010.7f,%c", degree_digits, whole, minutes_of, deg < 0.0 ? negative : positive);
    return std::string(buf);
  };
  char body[160];
  std::snprintf(body, sizeof body, "GPGGA,%02lld%02lld%05.2f,%s,%s,%d,%02d,%.1f,%.3f,M,%.3f,M,,",
                static_cast<long long>(hours), static_cast<long long>(minutes), seconds,
                angle(fix.latitude_deg, 2, 'N', 'S').c_str(), angle(fix.longitude_deg, 3, 'E', 'W').c_str(),
                fix.quality, fix.satellites, fix.hdop, fix.height_msl_m, fix.geoid_separation_m);
  unsigned checksum = 0;
  for (const char* p = body; *p != '\0'; ++p)
    checksum ^= static_cast<unsigned char>(*p);
  char out[200];
  std::snprintf(out, sizeof out, "$%s*%02X\r\n", body, checksum);
  return out;
}

}  // namespace trajroi::corrections
