// trajroid's YAML configuration: any text is a configuration or a config::ConfigError.
#include <cstdint>

#include "fuzz_input.hpp"
#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/daemon/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)trajroi::daemon::parse_daemon_config(trajroi::fuzz::as_text(data, size), "fuzz.yaml");
  } catch (const trajroi::config::ConfigError&) {
  }
  return 0;
}
