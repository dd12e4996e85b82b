#include <gtest/gtest.h>
#include <stdlib.h>

#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "trajroi/roi/cpu.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/reference_filter.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::roi {
namespace {

using V = Eigen::Vector2d;
constexpr double kInf = std::numeric_limits<double>::infinity();

RectangularRoiSet bend() {
  static const Trajectory t({V(0, 0), V(20, 0), V(30, 15)});
  std::vector<Centre> centres;
  place_centres(t, 0.0, kInf, 1.5, centres);
  return RectangularRoiSet(1.5, 3.0, centres, ZLimits{-1.0, 2.0});
}

TEST(ScanCalibration, TimesEveryScanTheCpuHasPicksTheFastestAndKAutoRunsIt) {
  unsetenv("TRAJROI_SIMD");
  const RectangularRoiSet set = bend();
  GridFilter<RectangularRoiSet> grid;
  grid.build(set);
  const ScanCalibration c = grid.calibrate();
  EXPECT_FALSE(c.forced);
  ASSERT_NE(c.chosen, SimdPath::kAuto);
  EXPECT_TRUE(cpu_has(c.chosen));
  double fastest = kInf;
  for (const SimdPath path : {SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
    const double ns = c.ns_per_point[static_cast<int>(path)];
    if (cpu_has(path)) {
      EXPECT_GT(ns, 0.0) << to_string(path);
      fastest = std::min(fastest, ns);
    } else {
      EXPECT_LT(ns, 0.0) << to_string(path) << " is not on this CPU and was not timed";
    }
  }
  // The chosen one is the fastest, or within the 3 % a wider scan is given.
  EXPECT_LE(c.ns_per_point[static_cast<int>(c.chosen)], fastest / 0.97 + 1e-12);
  EXPECT_EQ(GridFilter<RectangularRoiSet>::auto_path(), c.chosen);
  std::printf("[ calibration ] %s: %s\n", describe_machine().c_str(), to_string(c.chosen));

  // Whatever it chose, kAuto decides every point as the reference does.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> x(-5.0f, 35.0f), y(-5.0f, 20.0f), z(-2.0f, 3.0f);
  std::vector<PointXYZI> points(50'000);
  for (PointXYZI& p : points)
    p = {x(rng), y(rng), z(rng), 1.0f};
  IndexVector ref, fast;
  (void)reference_filter(set, std::span<const PointXYZI>(points), ref);
  (void)grid.filter(std::span<const PointXYZI>(points), fast);
  EXPECT_EQ(fast, ref);
  EXPECT_GT(ref.size(), 1000u);
}

TEST(ScanCalibration, TrajroiSimdForcesAPathWithoutTiming) {
  const RectangularRoiSet set = bend();
  GridFilter<RectangularRoiSet> grid;
  grid.build(set);
  setenv("TRAJROI_SIMD", "scalar", 1);
  const ScanCalibration c = grid.calibrate();
  unsetenv("TRAJROI_SIMD");
  EXPECT_TRUE(c.forced);
  EXPECT_EQ(c.chosen, SimdPath::kScalar);
  EXPECT_LT(c.ns_per_point[static_cast<int>(SimdPath::kScalar)], 0.0);
  EXPECT_EQ(GridFilter<RectangularRoiSet>::auto_path(), SimdPath::kScalar);
  (void)grid.calibrate();  // back to this machine's fastest for the tests that follow
  EXPECT_NE(GridFilter<RectangularRoiSet>::auto_path(), SimdPath::kAuto);
}

TEST(ScanCalibration, PathNamesRoundTripAndBadOnesAreRefused) {
  for (const SimdPath path :
       {SimdPath::kAuto, SimdPath::kAvx512, SimdPath::kAvx2, SimdPath::kSse2, SimdPath::kScalar}) {
    SimdPath back = SimdPath::kScalar;
    ASSERT_TRUE(simd_path_from_string(to_string(path), back));
    EXPECT_EQ(back, path);
  }
  SimdPath p = SimdPath::kSse2;
  EXPECT_TRUE(simd_path_from_string("", p));
  EXPECT_EQ(p, SimdPath::kAuto);
  EXPECT_FALSE(simd_path_from_string("avx", p));
  EXPECT_FALSE(simd_path_from_string("AVX2", p));
}

TEST(ScanCalibration, TheMachineIsNamed) {
  const std::string model = cpu_model();
  EXPECT_FALSE(model.empty());
  EXPECT_GE(usable_cores(), 1u);
  EXPECT_NE(describe_machine().find(std::to_string(usable_cores()) + " cores"), std::string::npos);
}

// The name and, on x86, the family and model numbers (what tells one generic VM name's
// processors apart), from the first processor's block; ARM has neither number.
TEST(ScanCalibration, TheModelLineCarriesFamilyAndModel) {
  const auto model_of = [](const std::string& text) {
    std::istringstream in(text);
    return cpu_model_from(in);
  };
  EXPECT_EQ(model_of("processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 25\nmodel\t\t: 17\n"
                     "model name\t: AMD EPYC\nstepping\t: 0\n\nprocessor\t: 1\ncpu family\t: 26\nmodel\t\t: 2\n"
                     "model name\t: other\n"),
            "AMD EPYC (family 25 model 17)");
  EXPECT_EQ(model_of("processor\t: 0\nvendor_id\t: GenuineIntel\ncpu family\t: 6\nmodel\t\t: 207\n"
                     "model name\t: Intel(R) Xeon(R) Processor\n"),
            "Intel(R) Xeon(R) Processor (family 6 model 207)");
  EXPECT_EQ(model_of("processor\t: 0\nBogoMIPS\t: 108.00\nCPU implementer\t: 0x41\nCPU part\t: 0xd08\n\n"
                     "Model\t\t: Raspberry Pi 4 Model B Rev 1.4\n"),
            "0xd08");
  EXPECT_EQ(model_of("processor\t: 0\ncpu family\t: 6\nmodel\t\t: 85\n"), "unknown CPU");
  EXPECT_EQ(model_of(""), "unknown CPU");
}

}  // namespace
}  // namespace trajroi::roi
