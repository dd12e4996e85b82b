#pragma once

// Whether memory is resident (mincore): the tests of the buffers made resident before use.
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace test_memory {

// Whether every page wholly inside [data, data + bytes) is resident.
inline bool resident(const void* data, std::size_t bytes) {
  const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(data) + page - 1) / page * page;
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) / page * page;
  if (end <= first) return true;
  std::vector<unsigned char> in((end - first) / page);
  if (::mincore(reinterpret_cast<void*>(first), end - first, in.data()) != 0) return false;
  return std::all_of(in.begin(), in.end(), [](unsigned char c) { return (c & 1U) != 0; });
}

// Whether any page wholly inside [data, data + bytes) is resident.
inline bool any_resident(const void* data, std::size_t bytes) {
  const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(data) + page - 1) / page * page;
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) / page * page;
  if (end <= first) return false;
  std::vector<unsigned char> in((end - first) / page);
  if (::mincore(reinterpret_cast<void*>(first), end - first, in.data()) != 0) return true;
  return std::any_of(in.begin(), in.end(), [](unsigned char c) { return (c & 1U) != 0; });
}

// Whether an array's whole capacity is resident.
template <typename Array>
bool resident_capacity(const Array& a) {
  return resident(a.data(), a.capacity() * sizeof(typename Array::value_type));
}

}  // namespace test_memory
