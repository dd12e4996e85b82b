#pragma once

#include <cstddef>

namespace trajroi::pipeline {

// Points placed and filtered together: those of three packets or more (384 at most each).
inline constexpr std::size_t kScratchPoints = 1024;

}  // namespace trajroi::pipeline
