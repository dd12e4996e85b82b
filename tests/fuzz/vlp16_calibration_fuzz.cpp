// Velodyne calibration files: the velodyne_pointcloud / nebula YAML and VeloView's XML, each
// told by its content.
#include <cstdint>
#include <stdexcept>

#include "fuzz_input.hpp"
#include "trajroi/vlp16/decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)trajroi::vlp16::parse_calibration_file(trajroi::fuzz::as_text(data, size), "fuzz.calibration");
  } catch (const std::exception&) {
  }
  return 0;
}
