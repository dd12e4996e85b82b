#pragma once

// Every benchmark program's context (printed before its figures) names the machine: the CPU
// model, the cores it may use and the SIMD scans the CPU has.
#include <benchmark/benchmark.h>

#include "trajroi/roi/cpu.hpp"

namespace trajroi::bench {

inline const int kMachineContext = (benchmark::AddCustomContext("machine", roi::describe_machine()), 0);

}  // namespace trajroi::bench
