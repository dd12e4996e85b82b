#include "trajroi/roi/cpu.hpp"

#include <sched.h>

#include <cstdio>
#include <fstream>

namespace trajroi::roi {

std::string describe(const ScanCalibration& calibration) {
  std::string text = to_string(calibration.chosen);
  if (calibration.forced) return text + " (forced by TRAJROI_SIMD)";
  std::string times;
  for (const SimdPath path : {SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
    const double ns = calibration.ns_per_point[static_cast<int>(path)];
    if (ns < 0.0) continue;
    char figure[32];
    std::snprintf(figure, sizeof figure, "%.2f", ns);
    times += (times.empty() ? "" : ", ") + std::string(to_string(path)) + " " + figure;
  }
  return text + " (" + times + " ns per point)";
}

std::string cpu_model() {
  std::ifstream info("/proc/cpuinfo");
  std::string line;
  while (std::getline(info, line)) {
    if (line.starts_with("model name") || line.starts_with("Model") || line.starts_with("CPU part")) {
      const std::size_t colon = line.find(':');
      if (colon == std::string::npos) continue;
      const std::size_t start = line.find_first_not_of(" \t", colon + 1);
      if (start != std::string::npos) return line.substr(start);
    }
  }
  return "unknown CPU";
}

unsigned usable_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return 1;
  return static_cast<unsigned>(CPU_COUNT(&set));
}

std::string describe_machine() {
  std::string text = cpu_model() + ", " + std::to_string(usable_cores()) + " cores,";
  for (const SimdPath path : {SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2}) {
    if (cpu_has(path)) text += std::string(" ") + to_string(path);
  }
  return text;
}

}  // namespace trajroi::roi
