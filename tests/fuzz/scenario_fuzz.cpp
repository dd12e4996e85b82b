// The simulator's scenario YAML: any text is a scenario or a config::ConfigError.
#include <cstdint>

#include "fuzz_input.hpp"
#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/sim/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)trajroi::sim::parse_scenario(trajroi::fuzz::as_text(data, size), "fuzz.yaml");
  } catch (const trajroi::config::ConfigError&) {
  }
  return 0;
}
