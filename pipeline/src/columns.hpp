#pragma once

// The sweep's point arrays grown in place (sweep_filter.cpp, sweep_merger.cpp).
#include <cstddef>

namespace trajroi::pipeline {

// `n` elements more at the end of `v`, unwritten (PointColumns' arrays do not zero what they
// grow by); where they start. Written then through the pointer: push_back would store the
// array's end at every element (the compiler cannot tell the arrays apart).
template <typename Array>
auto* grown(Array& v, std::size_t n) {
  const std::size_t at = v.size();
  v.resize(at + n);
  return v.data() + at;
}

}  // namespace trajroi::pipeline
