// roi::RoiChain against the paper's double loop: the chain it places is place_centres' chain,
// and the points it keeps are those the reference filter keeps on the same shapes, for both
// shapes, as the chain moves along an L-shaped trajectory and changes size.
#include "trajroi/roi/roi_chain.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "trajroi/roi/reference_filter.hpp"

namespace trajroi::roi {
namespace {

using V = Eigen::Vector2d;

std::vector<PointXYZI> scatter(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> xy(-5.0f, 35.0f), z(-2.0f, 4.0f);
  std::vector<PointXYZI> points(n);
  for (PointXYZI& p : points)
    p = {xy(rng), xy(rng), z(rng), 1.0f};
  return points;
}

TEST(RoiChain, KeepsWhatTheDoubleLoopKeepsForEitherShapeAsItMoves) {
  const Trajectory trajectory({V(0, 0), V(20, 0), V(20, 25)});
  const ZLimits z{-1.0, 3.0};
  const std::vector<PointXYZI> points = scatter(20'000, 5);
  struct Step {
    double s0_m, look_ahead_m, spacing_m;
    ChainSize size;
  };
  const Step steps[] = {
      {0.0, 12.0, 1.5, {1.5, 3.0, 2.5}}, {9.5, 15.0, 0.75, {2.25, 1.5, 4.0}}, {30.0, 100.0, 3.0, {1.0, 3.0, 1.0}}};
  for (const RoiShape shape : {RoiShape::kCircular, RoiShape::kRectangular}) {
    RoiChain chain(shape, ChainSize{1.0, 2.0, 3.0}, z);
    chain.reserve(64);
    for (const Step& step : steps) {
      chain.place(trajectory, step.s0_m, step.look_ahead_m, step.spacing_m, step.size);
      std::vector<Centre> expected_centres;
      place_centres(trajectory, step.s0_m, step.look_ahead_m, step.spacing_m, expected_centres);
      ASSERT_EQ(chain.centres().size(), expected_centres.size());
      for (std::size_t k = 0; k < expected_centres.size(); ++k) {
        EXPECT_EQ(chain.centres()[k].position, expected_centres[k].position);
        EXPECT_EQ(chain.centres()[k].s_m, expected_centres[k].s_m);
      }
      IndexVector kept, expected;
      chain.filter(points, kept);
      if (shape == RoiShape::kCircular) {
        (void)reference_filter(CircularRoiSet(step.size.radius_m, expected_centres, z), std::span(points), expected);
      } else {
        (void)reference_filter(RectangularRoiSet(step.size.height_m, step.size.width_m, expected_centres, z),
                               std::span(points), expected);
      }
      EXPECT_EQ(kept, expected) << to_string(shape) << " from s0 " << step.s0_m;
      EXPECT_GT(expected.size(), 100u);  // the scatter covers every chain
    }
  }
}

}  // namespace
}  // namespace trajroi::roi
