#include "trajroi/roi/metrics.hpp"

#include <stdexcept>
#include <string>

namespace trajroi::roi {
namespace {
double ratio_or_one(std::uint64_t numerator, std::uint64_t denominator) noexcept {
  return denominator == 0 ? 1.0 : static_cast<double>(numerator) / static_cast<double>(denominator);
}
}  // namespace

double Confusion::precision() const noexcept {
  return ratio_or_one(tp, tp + fp);
}
double Confusion::recall() const noexcept {
  return ratio_or_one(tp, tp + fn);
}
double Confusion::accuracy() const noexcept {
  return ratio_or_one(tp + tn, total());
}

Confusion confusion(std::span<const std::uint32_t> kept, std::span<const std::uint8_t> truth) {
  Confusion c;
  std::uint64_t positives = 0;
  for (const std::uint8_t t : truth)
    positives += t != 0 ? 1 : 0;
  for (const std::uint32_t i : kept) {
    if (i >= truth.size()) {
      throw std::out_of_range("kept index " + std::to_string(i) + " past " + std::to_string(truth.size()) + " labels");
    }
    if (truth[i] != 0) {
      ++c.tp;
    } else {
      ++c.fp;
    }
  }
  c.fn = positives - c.tp;
  c.tn = truth.size() - positives - c.fp;
  return c;
}

}  // namespace trajroi::roi
