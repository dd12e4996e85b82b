// The slow spells of a machine, found in a series of timed pieces of arithmetic: synthetic
// series with known spells (where they start and end, how slow), against what
// find_slow_spells reports.
#include "trajroi/eval/steadiness.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using trajroi::eval::find_slow_spells;
using trajroi::eval::PieceTiming;

// A piece of `full_us` every `every_s` for `seconds`; `slow(t)` gives the factor at time t.
template <typename Slow>
std::vector<PieceTiming> series(double seconds, double every_s, double full_us, Slow slow) {
  std::vector<PieceTiming> v;
  for (double t = 0.0; t < seconds; t += every_s)
    v.push_back({t, full_us * slow(t)});
  return v;
}

TEST(Steadiness, ASteadyMachineHasNoSpell) {
  const auto v =
      series(10.0, 0.005, 50.0, [](double t) { return 1.0 + 0.2 * ((static_cast<int>(t * 1000) % 7) / 7.0); });
  const auto s = find_slow_spells(v);
  EXPECT_EQ(s.pieces, v.size());
  EXPECT_NEAR(s.full_speed_us, 50.0, 1.5);
  EXPECT_TRUE(s.spells.empty());
  EXPECT_EQ(s.longest_ms(), 0.0);
  EXPECT_EQ(s.worst_factor(), 0.0);
}

TEST(Steadiness, SpellsAreFoundWithTheirLengthAndFactor) {
  // 100 ms at 12× from 1.0 s; one piece at 2.5× at 3.0 s; two spells 10 ms apart at 5.0 s (merged).
  const auto v = series(8.0, 0.005, 50.0, [](double t) {
    if (t >= 1.0 - 1e-9 && t < 1.1 - 1e-9) return 12.0;
    if (t > 2.999 && t < 3.001) return 2.5;
    if ((t >= 5.0 - 1e-9 && t < 5.02 - 1e-9) || (t >= 5.03 - 1e-9 && t < 5.05 - 1e-9)) return 4.0;
    return 1.0;
  });
  const auto s = find_slow_spells(v);
  EXPECT_DOUBLE_EQ(s.full_speed_us, 50.0);
  ASSERT_EQ(s.spells.size(), 3U);
  EXPECT_NEAR(s.spells[0].start_s, 1.0, 1e-6);
  EXPECT_NEAR(s.spells[0].end_s, 1.095 + 600e-6, 1e-6);  // the last slow piece's end
  EXPECT_EQ(s.spells[0].pieces, 20U);
  EXPECT_DOUBLE_EQ(s.spells[0].worst_factor, 12.0);
  EXPECT_NEAR(s.spells[1].start_s, 3.0, 1e-6);
  EXPECT_EQ(s.spells[1].pieces, 1U);
  EXPECT_DOUBLE_EQ(s.spells[1].worst_factor, 2.5);
  EXPECT_NEAR(s.spells[2].start_s, 5.0, 1e-6);
  EXPECT_NEAR(s.spells[2].end_s, 5.045 + 200e-6, 1e-6);
  EXPECT_EQ(s.spells[2].pieces, 8U);
  EXPECT_NEAR(s.longest_ms(), 95.6, 1e-3);
  EXPECT_DOUBLE_EQ(s.worst_factor(), 12.0);
  EXPECT_NEAR(s.slow_ms(), 95.6 + 0.125 + 45.2, 1e-3);
  // Apart by more than the merge distance, the two spells at 5 s stay two.
  EXPECT_EQ(find_slow_spells(v, 2.0, 0.005).spells.size(), 4U);
  // A piece at 2.5× is not slow at a threshold of 3×.
  EXPECT_EQ(find_slow_spells(v, 3.0).spells.size(), 2U);
}

TEST(Steadiness, FullSpeedIsKeptWhenTheMachineIsSlowMostOfTheTime) {
  // Slow at 3× 60 % of the time: the median is slow, the full speed is not.
  const auto v = series(10.0, 0.005, 40.0, [](double t) { return static_cast<int>(t * 10) % 10 < 6 ? 3.0 : 1.0; });
  const auto s = find_slow_spells(v);
  EXPECT_DOUBLE_EQ(s.full_speed_us, 40.0);
  EXPECT_DOUBLE_EQ(s.median_us, 120.0);
  EXPECT_EQ(s.spells.size(), 10U);
  EXPECT_DOUBLE_EQ(s.worst_factor(), 3.0);
}

TEST(Steadiness, NoPiecesNoSpells) {
  const auto s = find_slow_spells({});
  EXPECT_EQ(s.pieces, 0U);
  EXPECT_TRUE(s.spells.empty());
  EXPECT_EQ(s.slow_ms(), 0.0);
}

}  // namespace
