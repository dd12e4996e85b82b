#pragma once

// The TPV records of a gpsd regression `.chk` file (one JSON object per line, after some
// pseudo-NMEA lines). Only the fields the tests compare are read; a field gpsd left out is
// NaN (or empty for the time).
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace trajroi::test {

struct GpsdTpv {
  std::string time;  // "2017-07-19T08:50:01.000Z"
  int mode = 0;
  double lat = std::numeric_limits<double>::quiet_NaN();
  double lon = std::numeric_limits<double>::quiet_NaN();
  double alt_hae = std::numeric_limits<double>::quiet_NaN();
  double alt_msl = std::numeric_limits<double>::quiet_NaN();
};

inline double json_number(std::string_view line, std::string_view key) {
  std::string pattern(1, '"');
  pattern.append(key).append("\":");
  const std::size_t at = line.find(pattern);
  if (at == std::string_view::npos) return std::numeric_limits<double>::quiet_NaN();
  const std::string tail(line.substr(at + pattern.size(), 40));
  return std::strtod(tail.c_str(), nullptr);
}

// The text gpsd printed for `"key":` (a number as written, or a string without its quotes).
inline std::string json_raw(std::string_view line, std::string_view key) {
  std::string pattern(1, '"');
  pattern.append(key).append("\":");
  const std::size_t at = line.find(pattern);
  if (at == std::string_view::npos) return {};
  std::size_t begin = at + pattern.size();
  std::size_t end = line.find_first_of(",}", begin);
  if (line[begin] == '"') {
    ++begin;
    end = line.find('"', begin);
  }
  return std::string(line.substr(begin, end - begin));
}

inline std::vector<GpsdTpv> read_gpsd_tpv(const std::string& chk_text) {
  std::vector<GpsdTpv> out;
  std::istringstream in(chk_text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("{\"class\":\"TPV\"", 0) != 0) continue;
    GpsdTpv tpv;
    tpv.time = json_raw(line, "time");
    tpv.mode = static_cast<int>(json_number(line, "mode"));
    tpv.lat = json_number(line, "lat");
    tpv.lon = json_number(line, "lon");
    tpv.alt_hae = json_number(line, "altHAE");
    tpv.alt_msl = json_number(line, "altMSL");
    out.push_back(tpv);
  }
  return out;
}

}  // namespace trajroi::test
