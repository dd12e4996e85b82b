#pragma once

// The machine the scans run on, for the figures that depend on it (benchmarks, the daemon's
// scan calibration line): the CPU's model name and the cores this process may use.
#include <istream>
#include <string>

#include "trajroi/roi/grid_filter.hpp"

namespace trajroi::roi {

// "avx512 (avx512 1.55, avx2 1.65, sse2 2.64, scalar 6.04 ns per point)" or
// "sse2 (forced by TRAJROI_SIMD)": what a calibration chose and measured.
[[nodiscard]] std::string describe(const ScanCalibration& calibration);

// /proc/cpuinfo's "model name" (x86) or "Model"/"CPU part" line, with x86's family and model
// numbers: "AMD EPYC (family 25 model 17)". A virtual machine often shows a generic name that
// the numbers tell apart (Zen 3 is family 25 model 1, Zen 4 model 17). "unknown CPU" without
// a name.
[[nodiscard]] std::string cpu_model();
// The same from a /proc/cpuinfo text (each field's first occurrence: the first processor's).
[[nodiscard]] std::string cpu_model_from(std::istream& cpuinfo);
// The cores this process may run on (its affinity mask).
[[nodiscard]] unsigned usable_cores();
// "Intel(R) Xeon(R) …, 2 cores, AVX-512 AVX2 SSE2": model, cores and the scans the CPU has.
[[nodiscard]] std::string describe_machine();

}  // namespace trajroi::roi
