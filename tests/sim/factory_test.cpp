// The factory scenario end to end, against the paper's findings on its Gazebo factory
// (Section III-B): generated, decoded with the project's drivers, evaluated at the paper's
// keyframes. Release builds only (about 15 s); the README's tables come from the same run.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "test_data.hpp"
#include "trajroi/eval/scenario_eval.hpp"
#include "trajroi/sim/run_folder.hpp"

namespace trajroi::sim {
namespace {

TEST(FactoryScenario, ReproducesThePapersKeyframeFindings) {
  const std::filesystem::path scenario_file = std::string(TRAJROI_SOURCE_DIR) + "/config/scenarios/factory.yaml";
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("trajroi_factory_" + std::to_string(::getpid()));
  const std::string text = test::read_file(scenario_file);
  const RunReport report = write_run(load_scenario(scenario_file), text, dir);
  EXPECT_GT(report.realtime_factor(), 1.0);  // faster than real time

  const eval::ScenarioRun run(dir);
  std::uint64_t points = 0, complete = 0;
  run.for_each_frame([&](const vlp16::Frame& f, std::uint64_t, double) {
    points += f.points.size();
    complete += f.partial ? 0 : 1;
  });
  EXPECT_EQ(points, report.stats.points);
  EXPECT_EQ(run.labels().size(), points);
  EXPECT_NEAR(static_cast<double>(complete), 2234.0, 2.0);  // 223.6 s at 10 Hz

  const auto cases = eval::keyframe_cases(run, eval::PoseMode::kPerFiring);
  ASSERT_EQ(cases.size(), 3u);
  // Every row from one pass of the daemon's pipeline: shape × keyframe × {100 %, 25 %}.
  constexpr eval::RoiShape kShapes[] = {eval::RoiShape::kCircular, eval::RoiShape::kRectangular};
  constexpr int kRatios[] = {100, 25};
  const auto rows = eval::run_keyframe_rows(run, cases, kShapes, kRatios, 1, eval::PoseMode::kPerFiring);
  ASSERT_EQ(rows.size(), 12u);
  for (std::size_t s = 0; s < 2; ++s) {
    for (std::size_t k = 0; k < cases.size(); ++k) {
      const auto& c = cases[k];
      // Noise-free pose: the estimate is the truth to a millimetre.
      const TruePose truth = run.truth().at(c.time_ns);
      EXPECT_NEAR(c.robot_pose.translation().x(), truth.x_m, 2e-3) << c.keyframe.name;
      EXPECT_NEAR(c.robot_pose.translation().y(), truth.y_m, 2e-3) << c.keyframe.name;
      EXPECT_GT(c.points.size(), 20'000u);
      const eval::RoiShape shape = kShapes[s];
      const eval::KeyframeRow& far = rows[(s * cases.size() + k) * 2];
      const eval::KeyframeRow& near = rows[(s * cases.size() + k) * 2 + 1];
      ASSERT_EQ(far.ratio_pct, 100);
      ASSERT_EQ(near.ratio_pct, 25);
      ASSERT_EQ(near.shape, shape);
      ASSERT_EQ(near.keyframe, c.keyframe.name);
      const std::string what = c.keyframe.name + " " + std::string(eval::to_string(shape));
      // "All classification evaluation metrics have values of 0.99 or higher at the
      // shortest distance."
      EXPECT_GE(near.confusion.precision(), 0.99) << what;
      EXPECT_GE(near.confusion.recall(), 0.99) << what;
      EXPECT_GE(near.confusion.accuracy(), 0.99) << what;
      EXPECT_GE(near.confusion.recall(), far.confusion.recall()) << what;
      EXPECT_GT(near.centres.size(), far.centres.size()) << what;
      if (shape == eval::RoiShape::kCircular) {
        // Circles lie inside the corridor: no FP, whatever the spacing (Table 9).
        EXPECT_EQ(far.confusion.fp, 0u) << what;
        EXPECT_EQ(near.confusion.fp, 0u) << what;
      }
    }
  }
  // Keyframe 1 is straight for the whole look-ahead: the rectangles match the corridor.
  const eval::KeyframeRow& straight = rows[(1 * cases.size() + 0) * 2 + 1];
  EXPECT_EQ(straight.shape, eval::RoiShape::kRectangular);
  EXPECT_EQ(straight.confusion.fp, 0u);
  EXPECT_EQ(straight.confusion.fn, 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace trajroi::sim
