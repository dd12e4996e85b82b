#include "trajroi/roi/metrics.hpp"

#include <gtest/gtest.h>

#include "trajroi/roi/filter_stats.hpp"
#include "trajroi/roi/point.hpp"

namespace trajroi::roi {
namespace {

TEST(Metrics, CountsAndEquationThree) {
  const std::vector<std::uint8_t> truth{1, 1, 1, 0, 0, 1, 0};
  const IndexVector kept{0, 1, 3};
  const Confusion c = confusion(kept, truth);
  EXPECT_EQ(c.tp, 2u);
  EXPECT_EQ(c.fp, 1u);
  EXPECT_EQ(c.fn, 2u);
  EXPECT_EQ(c.tn, 2u);
  EXPECT_DOUBLE_EQ(c.precision(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(c.recall(), 0.5);
  EXPECT_DOUBLE_EQ(c.accuracy(), 4.0 / 7.0);
}

TEST(Metrics, PaperTableThreeFirstRow) {
  // straight data, circular, 150 %: TP 6234, FP 0, FN 6197, TN 8020 → 1, 0.5015, 0.6970
  const Confusion c{6234, 0, 6197, 8020};
  EXPECT_DOUBLE_EQ(c.precision(), 1.0);
  EXPECT_NEAR(c.recall(), 0.5015, 5e-5);
  EXPECT_NEAR(c.accuracy(), 0.6970, 5e-5);
}

TEST(Metrics, ZeroDenominatorsAreOne) {
  const Confusion nothing_kept{0, 0, 5, 5};
  EXPECT_DOUBLE_EQ(nothing_kept.precision(), 1.0);
  EXPECT_DOUBLE_EQ(nothing_kept.recall(), 0.0);
  const Confusion nothing_to_find{0, 3, 0, 5};
  EXPECT_DOUBLE_EQ(nothing_to_find.recall(), 1.0);
  EXPECT_DOUBLE_EQ(nothing_to_find.precision(), 0.0);
  const Confusion empty{};
  EXPECT_DOUBLE_EQ(empty.accuracy(), 1.0);
}

TEST(Metrics, RejectsIndexPastLabels) {
  const std::vector<std::uint8_t> truth{1, 0};
  const IndexVector kept{2};
  EXPECT_THROW((void)confusion(kept, truth), std::out_of_range);
}

TEST(Metrics, Compact) {
  const std::vector<PointXYZI> points{{1, 0, 0, 0}, {2, 0, 0, 0}, {3, 0, 0, 0}};
  const IndexVector kept{0, 2};
  std::vector<PointXYZI> out;
  compact(std::span<const PointXYZI>(points), kept, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].x, 3.0f);
}

}  // namespace
}  // namespace trajroi::roi
