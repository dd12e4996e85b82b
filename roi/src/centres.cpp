#include "trajroi/roi/centres.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace trajroi::roi {

void place_centres(const Trajectory& trajectory, double s0_m, double look_ahead_m, double spacing_m,
                   std::vector<Centre>& out) {
  if (!std::isfinite(spacing_m) || spacing_m <= 0.0) {
    throw std::invalid_argument("ROI spacing must be finite and positive, got " + std::to_string(spacing_m));
  }
  if (std::isnan(look_ahead_m) || look_ahead_m < 0.0) {
    throw std::invalid_argument("ROI look-ahead must be non-negative, got " + std::to_string(look_ahead_m));
  }
  const double length = trajectory.length_m();
  const double s0 = std::isnan(s0_m) ? 0.0 : std::clamp(s0_m, 0.0, length);
  // The span from s0, taken as the look-ahead itself when the trajectory is long enough
  // (s0 + L − s0 may lose the last bit, and a look-ahead of exactly n spacings must give
  // n + 1 centres); a relative slack of 1e-9 spacing absorbs the rounding of L / d.
  const double span = s0 + look_ahead_m <= length ? look_ahead_m : length - s0;
  const double steps = std::floor(span / spacing_m + 1e-9);
  if (!(steps < static_cast<double>(kMaxCentres))) {
    throw std::invalid_argument("ROI spacing " + std::to_string(spacing_m) + " m over " + std::to_string(span) +
                                " m gives more than " + std::to_string(kMaxCentres) + " centres");
  }
  const auto count = static_cast<std::size_t>(steps) + 1;
  out.clear();
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const double s = std::min(s0 + static_cast<double>(k) * spacing_m, length);
    out.push_back(Centre{trajectory.point_at(s), trajectory.heading_at(s), s});
  }
}

}  // namespace trajroi::roi
