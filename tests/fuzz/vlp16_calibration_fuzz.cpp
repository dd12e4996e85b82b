// The VLP-16 calibration YAML (velodyne_pointcloud / nebula format).
#include <cstdint>
#include <stdexcept>

#include "fuzz_input.hpp"
#include "trajroi/vlp16/decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)trajroi::vlp16::parse_calibration_yaml(trajroi::fuzz::as_text(data, size), "fuzz.yaml");
  } catch (const std::exception&) {
  }
  return 0;
}
