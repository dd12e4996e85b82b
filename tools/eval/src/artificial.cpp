#include "trajroi/eval/artificial.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/reference_filter.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::eval {

std::string_view to_string(ArtificialData data) noexcept {
  return data == ArtificialData::kStraight ? "straight" : "curved";
}

namespace {

constexpr double kGridStep_m = 0.2;
constexpr double kCurveCentreX_m = 0.0;
constexpr double kCurveCentreY_m = 50.0;
constexpr double kCurveRadius_m = 50.0;
constexpr int kArcChords = 7854;  // ≈ 1 cm chords over 25π m: sagitta 2.5e-7 m

roi::Trajectory curved_trajectory() {
  std::vector<Eigen::Vector2d> waypoints;
  waypoints.reserve(kArcChords + 2);
  for (int k = 0; k < kArcChords; ++k) {
    const double phi = std::numbers::pi / 2.0 * k / kArcChords;
    waypoints.emplace_back(kCurveRadius_m * std::sin(phi), kCurveCentreY_m - kCurveRadius_m * std::cos(phi));
  }
  waypoints.emplace_back(50.0, 50.0);
  waypoints.emplace_back(50.0, 53.0);
  return roi::Trajectory(std::move(waypoints));
}

double curve_rho(double x, double y) {
  return std::hypot(x - kCurveCentreX_m, y - kCurveCentreY_m);
}

}  // namespace

ArtificialScene make_artificial_scene(ArtificialData data) {
  if (data == ArtificialData::kStraight) {
    ArtificialScene scene{data, {}, {}, roi::Trajectory({{0.0, 0.0}, {83.0, 0.0}})};
    for (int i = 0; i <= 400; ++i) {
      for (int j = 0; j <= 50; ++j) {
        const double x = kGridStep_m * i;
        const double y = -5.0 + kGridStep_m * j;
        scene.points.push_back({x, y, 0.0});
        scene.truth.push_back(std::abs(y) <= kTruthHalfWidth_m ? 1 : 0);
      }
    }
    return scene;
  }
  ArtificialScene scene{data, {}, {}, curved_trajectory()};
  for (int i = 0; i <= 275; ++i) {
    for (int j = 0; j <= 275; ++j) {
      const double x = kGridStep_m * i;
      const double y = -5.0 + kGridStep_m * j;
      const double rho = curve_rho(x, y);
      if (rho < 45.0 || rho > 55.0) continue;
      scene.points.push_back({x, y, 0.0});
      scene.truth.push_back(std::abs(rho - kCurveRadius_m) <= kTruthHalfWidth_m ? 1 : 0);
    }
  }
  return scene;
}

namespace {

template <typename RoiSet>
ArtificialRow run_with(const ArtificialScene& scene, ArtificialRow row, int reps, auto make_set) {
  const std::span<const roi::PointXYZd> points(scene.points);
  roi::IndexVector reference_kept;
  reference_kept.reserve(points.size());
  row.kept.reserve(points.size());
  row.reference = time_repeated(reps, [&] {
    const RoiSet set = make_set(row.centres);
    roi::reference_filter(set, points, reference_kept);
  });
  roi::GridFilter<RoiSet> grid;
  row.fast = time_repeated(reps, [&] {
    const RoiSet set = make_set(row.centres);
    grid.build(set);
    grid.filter(points, row.kept);
  });
  row.fast_equals_reference = row.kept == reference_kept;
  row.confusion = roi::confusion(row.kept, scene.truth);
  return row;
}

}  // namespace

ArtificialRow run_artificial_row(const ArtificialScene& scene, RoiShape shape, int ratio_pct, int reps) {
  if (ratio_pct <= 0) throw std::invalid_argument("spacing ratio must be positive");
  ArtificialRow row{};
  row.data = scene.data;
  row.shape = shape;
  row.ratio_pct = ratio_pct;
  const double size_along = shape == RoiShape::kCircular ? kCircleDiameter_m : kRectHeight_m;
  row.spacing_m = roi::spacing_from_ratio(ratio_pct / 100.0, size_along);
  roi::place_centres(scene.trajectory, 0.0, std::numeric_limits<double>::infinity(), row.spacing_m, row.centres);
  if (shape == RoiShape::kCircular) {
    return run_with<roi::CircularRoiSet>(scene, std::move(row), reps, [](const auto& centres) {
      return roi::CircularRoiSet(kCircleDiameter_m / 2.0, centres);
    });
  }
  return run_with<roi::RectangularRoiSet>(scene, std::move(row), reps, [](const auto& centres) {
    return roi::RectangularRoiSet(kRectHeight_m, kRectWidth_m, centres);
  });
}

}  // namespace trajroi::eval
