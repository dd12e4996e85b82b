#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "trajroi/eval/timing.hpp"
#include "trajroi/roi/centres.hpp"
#include "trajroi/roi/filter_stats.hpp"
#include "trajroi/roi/metrics.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/trajectory.hpp"

namespace trajroi::eval {

// The paper's artificial-frame experiment (Section III-A, Tables 2–5), set up exactly as
// ../shared/paper/REPRODUCTION.md reconstructs it.
enum class ArtificialData { kStraight, kCurved };
using roi::RoiShape;

[[nodiscard]] std::string_view to_string(ArtificialData data) noexcept;
using roi::to_string;

inline constexpr std::array<int, 7> kPaperRatiosPct{150, 125, 100, 75, 50, 25, 10};
inline constexpr double kCircleDiameter_m = 6.0;
inline constexpr double kRectHeight_m = 3.0;  // a, along the tangent
inline constexpr double kRectWidth_m = 6.0;   // b, across
inline constexpr double kTruthHalfWidth_m = 3.0;

struct ArtificialScene {
  ArtificialData data;
  std::vector<roi::PointXYZd> points;  // z = 0; robot pose = identity, so global = sensor
  std::vector<std::uint8_t> truth;     // 1 inside the ground-truth ROI
  roi::Trajectory trajectory;
};

// Straight: x = 0.2 i (i ≤ 400), y = −5 + 0.2 j (j ≤ 50); trajectory (0,0)→(83,0); truth
// |y| ≤ 3. Curved: the grid x = 0.2 i, y = −5 + 0.2 j (i, j ≤ 275) kept where 45 ≤ ρ ≤ 55,
// ρ = ‖p − (0, 50)‖; trajectory the quarter circle of radius 50 about (0, 50) from (0, 0) to
// (50, 50) as a polyline of 1 cm chords, then straight to (50, 53); truth 47 ≤ ρ ≤ 53.
[[nodiscard]] ArtificialScene make_artificial_scene(ArtificialData data);

struct ArtificialRow {
  ArtificialData data;
  RoiShape shape;
  int ratio_pct;
  double spacing_m;
  std::vector<roi::Centre> centres;
  roi::Confusion confusion;
  roi::IndexVector kept;       // the fast filter's output
  bool fast_equals_reference;  // kept indices identical, point for point
  TimingStats reference;
  TimingStats fast;
};

// One row of Table 3 (circular) or Table 5 (rectangular): centres from arc length 0 to the
// end, spacing ratio × diameter (circular) or × height (rectangular); each method timed over
// `reps` calls (centre geometry, and the grid for the fast one, included in every call).
[[nodiscard]] ArtificialRow run_artificial_row(const ArtificialScene& scene, RoiShape shape, int ratio_pct, int reps);

}  // namespace trajroi::eval
