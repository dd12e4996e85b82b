#pragma once

// Makers of configuration keys shared by the key table's sources (config_keys.cpp,
// config_keys_sensors.cpp): numbers, counts and flags held in a DaemonConfig field reached by a
// generic lambda (which works on a const DaemonConfig too). Internal to daemon/src.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "config_keys.hpp"
#include "config_read.hpp"

namespace trajroi::daemon::config_keys_detail {

using config::MapReader;
using config_read::count;
using config_read::format_mounting;
using config_read::format_number;
using config_read::format_thread;
using config_read::format_vector;
using config_read::ipv4;
using config_read::optional_number;
using config_read::port;
using config_read::read_mounting;
using config_read::read_thread;
using config_read::resolve;
using Dir = std::filesystem::path;

inline std::string flag(bool v) {
  return v ? "true" : "false";
}

// How a number key is checked: > 0, ≥ 0, or any.
enum class Sign { kAny, kPositive, kNonNegative };

// A count in [lo, hi] held in a std::size_t of DaemonConfig (reached by `get`, a generic
// lambda that works on a const DaemonConfig too).
template <typename Get>
inline ConfigKey count_key(std::string_view path, std::string_view meaning, std::size_t lo, std::size_t hi, Get get) {
  return {path,
          "integer",
          meaning,
          false,
          [lo, hi, get](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
            std::size_t& v = get(c);
            v = count(m, k, v, lo, hi);
          },
          [get](const DaemonConfig& c) { return format_number(static_cast<double>(get(c))); }};
}

// A number held in a double of DaemonConfig (reached by `get`), checked by `sign`.
template <typename Get>
ConfigKey real_key(std::string_view path, std::string_view type, std::string_view meaning, Sign sign, Get get) {
  return {path,
          type,
          meaning,
          false,
          [sign, get](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
            double& v = get(c);
            v = sign == Sign::kPositive      ? m.positive(k, v)
                : sign == Sign::kNonNegative ? m.non_negative(k, v)
                                             : m.number(k, v);
          },
          [get](const DaemonConfig& c) { return format_number(get(c)); }};
}

// A boolean held in DaemonConfig (reached by `get`).
template <typename Get>
ConfigKey flag_key(std::string_view path, std::string_view meaning, Get get) {
  return {path,
          "boolean",
          meaning,
          false,
          [get](MapReader& m, std::string_view k, DaemonConfig& c, const Dir&) {
            bool& v = get(c);
            v = m.boolean(k, v);
          },
          [get](const DaemonConfig& c) { return flag(get(c)); }};
}

// The keys of the global frame, the trajectory and the sensors (config_keys_sensors.cpp).
void add_sensor_keys(std::vector<ConfigKey>& k);

}  // namespace trajroi::daemon::config_keys_detail
