// The paper's artificial-frame tables (3 and 5), reproduced as REPRODUCTION.md sets them up.
#include "trajroi/eval/artificial.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace trajroi::eval {
namespace {

struct PaperRow {
  int ratio_pct;
  std::size_t num_roi;
  std::uint64_t tp;
  std::uint64_t fp;
  std::uint64_t fn;
  std::uint64_t tn;
};

// Table 3 (circular) and Table 5 (rectangular), straight data.
constexpr PaperRow kStraightCircular[] = {{150, 10, 6234, 0, 6197, 8020}, {125, 12, 7422, 0, 5009, 8020},
                                          {100, 14, 9460, 0, 2971, 8020}, {75, 19, 10696, 0, 1735, 8020},
                                          {50, 28, 11467, 0, 964, 8020},  {25, 56, 11683, 0, 748, 8020},
                                          {10, 139, 11897, 0, 534, 8020}};
constexpr PaperRow kStraightRectangular[] = {{150, 19, 8525, 0, 3906, 8020}, {125, 23, 10137, 0, 2294, 8020},
                                             {100, 28, 12431, 0, 0, 8020},   {75, 37, 12431, 0, 0, 8020},
                                             {50, 56, 12431, 0, 0, 8020},    {25, 111, 12431, 0, 0, 8020},
                                             {10, 277, 12431, 0, 0, 8020}};
// Curved data: the paper's #ROI and TP (FP and FN depend on its 11,804-point truth).
constexpr PaperRow kCurvedCircular[] = {{150, 10, 6060, 0, 5744, 7874}, {125, 11, 7435, 0, 4369, 7874},
                                        {100, 14, 9288, 0, 2516, 7874}, {75, 19, 10560, 0, 1244, 7874},
                                        {50, 28, 11287, 0, 517, 7874},  {25, 55, 11671, 0, 133, 7874},
                                        {10, 136, 11777, 0, 27, 7874}};
constexpr PaperRow kCurvedRectangular[] = {
    {150, 19, 7883, 17, 0, 0}, {125, 22, 9434, 26, 0, 0},  {100, 28, 11621, 23, 0, 0}, {75, 37, 11791, 29, 0, 0},
    {50, 55, 11799, 35, 0, 0}, {25, 109, 11799, 42, 0, 0}, {10, 272, 11802, 49, 0, 0}};

TEST(ArtificialScene, SizesAndTruthMatchTheSetUp) {
  const ArtificialScene straight = make_artificial_scene(ArtificialData::kStraight);
  EXPECT_EQ(straight.points.size(), 20'451u);
  EXPECT_EQ(std::count(straight.truth.begin(), straight.truth.end(), 1), 12'431);
  EXPECT_DOUBLE_EQ(straight.trajectory.length_m(), 83.0);
  const ArtificialScene curved = make_artificial_scene(ArtificialData::kCurved);
  EXPECT_EQ(curved.points.size(), 19'678u);
  EXPECT_EQ(std::count(curved.truth.begin(), curved.truth.end(), 1), 11'805);  // paper: 11,804
  EXPECT_NEAR(curved.trajectory.length_m(), 25.0 * std::numbers::pi + 3.0, 1e-5);
}

void expect_straight_rows_exact(RoiShape shape, std::span<const PaperRow> rows) {
  const ArtificialScene scene = make_artificial_scene(ArtificialData::kStraight);
  for (const PaperRow& p : rows) {
    const ArtificialRow r = run_artificial_row(scene, shape, p.ratio_pct, 1);
    SCOPED_TRACE(std::string(to_string(shape)) + " " + std::to_string(p.ratio_pct) + " %");
    EXPECT_TRUE(r.fast_equals_reference);
    EXPECT_EQ(r.centres.size(), p.num_roi);
    EXPECT_EQ(r.confusion.tp, p.tp);
    EXPECT_EQ(r.confusion.fp, p.fp);
    EXPECT_EQ(r.confusion.fn, p.fn);
    EXPECT_EQ(r.confusion.tn, p.tn);
  }
}

void expect_curved_rows_close(RoiShape shape, std::span<const PaperRow> rows) {
  const ArtificialScene scene = make_artificial_scene(ArtificialData::kCurved);
  for (const PaperRow& p : rows) {
    const ArtificialRow r = run_artificial_row(scene, shape, p.ratio_pct, 1);
    SCOPED_TRACE(std::string(to_string(shape)) + " " + std::to_string(p.ratio_pct) + " %");
    EXPECT_TRUE(r.fast_equals_reference);
    EXPECT_EQ(r.centres.size(), p.num_roi);
    const double tp = static_cast<double>(r.confusion.tp);
    EXPECT_LE(std::abs(tp - static_cast<double>(p.tp)), 0.001 * static_cast<double>(p.tp))
        << "TP " << r.confusion.tp << " vs paper " << p.tp;
    if (shape == RoiShape::kCircular) {
      EXPECT_EQ(r.confusion.fp, 0u);  // circles stay inside the corridor
    }
  }
}

TEST(PaperTable3, StraightCircularExact) {
  expect_straight_rows_exact(RoiShape::kCircular, kStraightCircular);
}
TEST(PaperTable5, StraightRectangularExact) {
  expect_straight_rows_exact(RoiShape::kRectangular, kStraightRectangular);
}
TEST(PaperTable3, CurvedCircularWithinPointOnePercent) {
  expect_curved_rows_close(RoiShape::kCircular, kCurvedCircular);
}
TEST(PaperTable5, CurvedRectangularWithinPointOnePercent) {
  expect_curved_rows_close(RoiShape::kRectangular, kCurvedRectangular);
}

TEST(ArtificialRow, TimingIsReported) {
  const ArtificialScene scene = make_artificial_scene(ArtificialData::kStraight);
  const ArtificialRow r = run_artificial_row(scene, RoiShape::kCircular, 10, 3);
  EXPECT_GT(r.reference.avg_ms, 0.0);
  EXPECT_LE(r.reference.min_ms, r.reference.avg_ms);
  EXPECT_LE(r.reference.avg_ms, r.reference.max_ms);
  EXPECT_GT(r.fast.avg_ms, 0.0);
  EXPECT_THROW((void)run_artificial_row(scene, RoiShape::kCircular, 0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace trajroi::eval
