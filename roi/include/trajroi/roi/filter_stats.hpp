#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace trajroi::roi {

// An allocator whose value-less construct() default-initialises: resize() on a vector of
// integers then leaves new elements unwritten instead of zeroing them. The fast filter sizes
// its output for every point up front and writes each index unconditionally, so a zeroing
// resize would cost a memset of the whole output per call.
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  using std::allocator<T>::allocator;
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// Indices of kept points, ascending. A std::vector in every respect but resize().
using IndexVector = std::vector<std::uint32_t, DefaultInitAllocator<std::uint32_t>>;

// What one filter call saw. Every input point is in exactly one of: kept, non_finite,
// outside_z, or rejected by the XY test (input − the other three).
struct FilterStats {
  std::size_t input = 0;
  std::size_t kept = 0;
  std::size_t non_finite = 0;  // x, y or z NaN or infinite: never kept
  std::size_t outside_z = 0;   // finite, but outside the z limits
};

// The checks every filter applies before its XY test, in the same order, so that their
// statistics agree too.
enum class Precheck : unsigned char { kPass, kNonFinite, kOutsideZ };

template <typename ZLimitsT>
[[nodiscard]] inline Precheck precheck(const ZLimitsT& z_limits, double x, double y, double z) noexcept {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return Precheck::kNonFinite;
  if (!z_limits.contains(z)) return Precheck::kOutsideZ;
  return Precheck::kPass;
}

inline void count_rejection(FilterStats& stats, Precheck result) noexcept {
  if (result == Precheck::kNonFinite) ++stats.non_finite;
  if (result == Precheck::kOutsideZ) ++stats.outside_z;
}

}  // namespace trajroi::roi
