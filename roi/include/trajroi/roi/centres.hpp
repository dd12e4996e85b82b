#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <vector>

#include "trajroi/roi/trajectory.hpp"

namespace trajroi::roi {

// One ROI centre c_k on the trajectory with its tangent angle θ_k.
struct Centre {
  Eigen::Vector2d position;  // global frame, metres
  double theta_rad;          // trajectory heading at s_m, counter-clockwise from +x
  double s_m;                // arc length of the centre
};

// Most centres one chain may hold; more means a spacing far too small for the look-ahead.
inline constexpr std::size_t kMaxCentres = 1'000'000;

// Places c_k = P(s0 + k·d), θ_k = heading(s0 + k·d) for k = 0 … ⌊(s1 − s0)/d⌋, where s0 is
// clamped to [0, length] and s1 = min(s0 + look_ahead, length) (look_ahead may be +∞: to the
// end); a look-ahead of exactly n spacings gives n + 1 centres whatever the rounding of
// s0 + look_ahead. `out` is cleared and refilled; its capacity is reused, so a warm caller allocates
// nothing. Throws std::invalid_argument when spacing_m is not finite and positive, when
// look_ahead_m is negative or NaN, or when the chain would exceed kMaxCentres.
void place_centres(const Trajectory& trajectory, double s0_m, double look_ahead_m, double spacing_m,
                   std::vector<Centre>& out);

// The paper gives the spacing as a ratio of the ROI's size along the trajectory: the
// diameter 2r for circles, the height a for rectangles (150 % → d = 1.5 · size).
[[nodiscard]] inline double spacing_from_ratio(double ratio, double size_along_m) noexcept {
  return ratio * size_along_m;
}

}  // namespace trajroi::roi
