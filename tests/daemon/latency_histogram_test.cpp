// The whole-run latency histogram: quantiles against sorting the same values (to its 10 µs
// bins), above-range values, and fixed memory whatever the count.
#include "trajroi/daemon/latency_histogram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace {

using trajroi::daemon::LatencyHistogram;

TEST(LatencyHistogram, QuantilesMatchSortingToOneBin) {
  std::mt19937 random(3);
  std::lognormal_distribution<double> latency(-0.7, 0.6);  // ≈ 0.5 ms median, a tail
  LatencyHistogram h;
  std::vector<double> all;
  for (int i = 0; i < 100'000; ++i) {
    const double ms = latency(random);
    h.add(ms);
    all.push_back(ms);
  }
  std::sort(all.begin(), all.end());
  EXPECT_EQ(h.count(), all.size());
  for (const double q : {0.5, 0.9, 0.99, 0.999}) {
    const double exact = all[static_cast<std::size_t>(std::ceil(q * static_cast<double>(all.size()))) - 1];
    EXPECT_GE(h.quantile(q), exact) << q;
    EXPECT_LE(h.quantile(q), exact + LatencyHistogram::kBin_ms) << q;
  }
  EXPECT_DOUBLE_EQ(h.quantile(1.0), all.back());
}

TEST(LatencyHistogram, EmptyAndAboveRange) {
  LatencyHistogram h;
  EXPECT_EQ(h.quantile(0.5), 0.0);
  h.add(0.2);
  h.add(250.0);  // beyond the 100 ms of bins
  h.add(-1.0);   // a clock step: counted in the first bin
  EXPECT_EQ(h.count(), 3u);
  EXPECT_DOUBLE_EQ(h.quantile(0.99), 250.0);
  EXPECT_NEAR(h.quantile(0.5), 0.2, LatencyHistogram::kBin_ms);
  EXPECT_LE(h.quantile(0.1), LatencyHistogram::kBin_ms);
}

}  // namespace
