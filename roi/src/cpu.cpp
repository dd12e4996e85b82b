#include "trajroi/roi/cpu.hpp"

#include <sched.h>

#include <cstdio>
#include <fstream>
#include <istream>
#include <string_view>

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

std::string cpu_model_from(std::istream& cpuinfo) {
  std::string name, family, model;
  std::string line;
  const auto value = [&line] {
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) return std::string();
    const std::size_t start = line.find_first_not_of(" \t", colon + 1);
    return start == std::string::npos ? std::string() : line.substr(start);
  };
  while (std::getline(cpuinfo, line)) {
    const auto field = [&line](std::string_view key) {
      return line.starts_with(key) && line.find_first_not_of(" \t", key.size()) == line.find(':');
    };
    if (name.empty() && (field("model name") || field("Model") || field("CPU part"))) {
      name = value();
    } else if (family.empty() && field("cpu family")) {
      family = value();
    } else if (model.empty() && field("model")) {
      model = value();
    }
  }
  if (name.empty()) return "unknown CPU";
  if (!family.empty() && !model.empty()) name += " (family " + family + " model " + model + ")";
  return name;
}

std::string cpu_model() {
  std::ifstream info("/proc/cpuinfo");
  return cpu_model_from(info);
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
