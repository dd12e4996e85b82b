#pragma once

// Every key of trajroid's configuration, held once: its path, type and meaning, how it is read
// into DaemonConfig (the struct's initialisers are the defaults) and how its effective value is
// shown. The parse, --check-config's summary (describe()) and the reference
// (config_reference(): docs/configuration.md, `trajroid --config-reference`) all walk this
// table. Internal to daemon/src.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/daemon/config.hpp"

namespace trajroi::daemon {

struct ConfigKey {
  std::string_view path;     // "lidar.min_range_m": the maps, then the key
  std::string_view type;     // "number ≥ 0", "circular | rectangular", …
  std::string_view meaning;  // one line for the reference
  bool required = false;     // no default: the file must give it
  // Reads the key `name` from its map `m` into `c` (relative paths against `dir`); leaves the
  // default when the key is absent; throws config::ConfigError naming file, line, key, value.
  std::function<void(config::MapReader& m, std::string_view name, DaemonConfig& c, const std::filesystem::path& dir)>
      read;
  std::function<std::string(const DaemonConfig& c)> show;  // the effective value, as YAML
};

struct ConfigSection {
  std::string_view name;     // "lidar"
  std::string_view title;    // "The LiDAR"
  std::string_view meaning;  // a paragraph for the reference
  bool required = false;
  // Checks between the section's keys, run once they are read (empty: none).
  std::function<void(config::MapReader& m, const DaemonConfig& c)> check;
};

[[nodiscard]] const std::vector<ConfigKey>& config_keys();
[[nodiscard]] const std::vector<ConfigSection>& config_sections();

}  // namespace trajroi::daemon
