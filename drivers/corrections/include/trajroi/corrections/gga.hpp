#pragma once

// The NMEA 0183 GGA sentence a rover sends a VRS caster (its position, so that the caster
// computes corrections for a virtual base station beside it). Pure.
#include <cstdint>
#include <string>

namespace trajroi::corrections {

struct GgaFix {
  std::int64_t utc_ns = 0;  // the fix's time (only its time of day is sent)
  double latitude_deg = 0.0, longitude_deg = 0.0;
  double height_msl_m = 0.0;        // above mean sea level
  double geoid_separation_m = 0.0;  // ellipsoid − geoid (height above the ellipsoid − height_msl)
  int quality = 1;                  // 0 none, 1 GNSS, 2 differential, 4 RTK fixed, 5 RTK float
  int satellites = 0;
  double hdop = 99.9;
};

// "$GPGGA,hhmmss.ss,ddmm.mmmmmmm,N,dddmm.mmmmmmm,E,q,ss,h.h,a.aaa,M,g.ggg,M,,*CS\r\n".
[[nodiscard]] std::string gga_sentence(const GgaFix& fix);

}  // namespace trajroi::corrections
