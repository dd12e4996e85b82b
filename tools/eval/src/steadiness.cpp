#include "trajroi/eval/steadiness.hpp"

#include <algorithm>

namespace trajroi::eval {

double Steadiness::longest_ms() const noexcept {
  double longest = 0.0;
  for (const SlowSpell& s : spells)
    longest = std::max(longest, (s.end_s - s.start_s) * 1e3);
  return longest;
}

double Steadiness::worst_factor() const noexcept {
  double worst = 0.0;
  for (const SlowSpell& s : spells)
    worst = std::max(worst, s.worst_factor);
  return worst;
}

double Steadiness::slow_ms() const noexcept {
  double total = 0.0;
  for (const SlowSpell& s : spells)
    total += (s.end_s - s.start_s) * 1e3;
  return total;
}

Steadiness find_slow_spells(std::span<const PieceTiming> pieces, double factor, double merge_s) {
  Steadiness result;
  result.pieces = pieces.size();
  if (pieces.empty()) return result;
  std::vector<double> durations;
  durations.reserve(pieces.size());
  for (const PieceTiming& p : pieces)
    durations.push_back(p.duration_us);
  const auto at = [&durations](double q) {
    auto k = static_cast<std::size_t>(q * static_cast<double>(durations.size() - 1));
    std::nth_element(durations.begin(), durations.begin() + static_cast<std::ptrdiff_t>(k), durations.end());
    return durations[k];
  };
  result.full_speed_us = at(0.1);
  result.median_us = at(0.5);
  if (!(result.full_speed_us > 0.0)) return result;
  const double threshold_us = factor * result.full_speed_us;
  for (const PieceTiming& p : pieces) {
    if (p.duration_us <= threshold_us) continue;
    const double end_s = p.start_s + p.duration_us * 1e-6;
    const double f = p.duration_us / result.full_speed_us;
    if (!result.spells.empty() && p.start_s - result.spells.back().end_s < merge_s) {
      SlowSpell& s = result.spells.back();
      s.end_s = std::max(s.end_s, end_s);
      s.worst_factor = std::max(s.worst_factor, f);
      ++s.pieces;
    } else {
      result.spells.push_back({p.start_s, end_s, f, 1});
    }
  }
  return result;
}

}  // namespace trajroi::eval
