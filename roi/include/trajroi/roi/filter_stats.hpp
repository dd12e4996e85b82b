#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace trajroi::roi {

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
[[nodiscard]] inline Precheck precheck(const ZLimitsT& z_limits, double x, double y,
                                       double z) noexcept {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return Precheck::kNonFinite;
  if (!z_limits.contains(z)) return Precheck::kOutsideZ;
  return Precheck::kPass;
}

inline void count(FilterStats& stats, Precheck result) noexcept {
  if (result == Precheck::kNonFinite) ++stats.non_finite;
  if (result == Precheck::kOutsideZ) ++stats.outside_z;
}

}  // namespace trajroi::roi
