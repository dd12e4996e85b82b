#pragma once

// Whether memory is resident (mincore): the tests of the buffers made resident before use.
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace test_memory {

// The residence (mincore) of each page wholly inside [data, data + bytes): empty when no page
// is, nullopt when mincore fails.
inline std::optional<std::vector<bool>> page_residence(const void* data, std::size_t bytes) {
  const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(data) + page - 1) / page * page;
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) / page * page;
  if (end <= first) return std::vector<bool>{};
  std::vector<unsigned char> in((end - first) / page);
  if (::mincore(reinterpret_cast<void*>(first), end - first, in.data()) != 0) return std::nullopt;
  std::vector<bool> resident(in.size());
  for (std::size_t i = 0; i < in.size(); ++i)
    resident[i] = (in[i] & 1U) != 0;
  return resident;
}

// Whether every page wholly inside [data, data + bytes) is resident (false if mincore fails).
inline bool resident(const void* data, std::size_t bytes) {
  const auto pages = page_residence(data, bytes);
  return pages && std::all_of(pages->begin(), pages->end(), [](bool r) { return r; });
}

// Whether any page wholly inside [data, data + bytes) is resident (true if mincore fails).
inline bool any_resident(const void* data, std::size_t bytes) {
  const auto pages = page_residence(data, bytes);
  return !pages || std::any_of(pages->begin(), pages->end(), [](bool r) { return r; });
}

// Whether an array's whole capacity is resident.
template <typename Array>
bool resident_capacity(const Array& a) {
  return resident(a.data(), a.capacity() * sizeof(typename Array::value_type));
}

}  // namespace test_memory
