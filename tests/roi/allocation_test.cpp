// After warm-up, a filter call allocates nothing: counted by replacing global operator new
// in this test executable.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <limits>
#include <new>

#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/point.hpp"
#include "trajroi/roi/reference_filter.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/transform.hpp"

namespace {
std::atomic<std::size_t> g_allocations{0};
}

// Replacing the global allocation functions with malloc/free is what the standard allows;
// GCC cannot see that the pair matches.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace trajroi::roi {
namespace {

TEST(Allocation, WarmFilterCallsAllocateNothing) {
  const Trajectory t({Eigen::Vector2d(0, 0), Eigen::Vector2d(30, 0), Eigen::Vector2d(30, 30)});
  std::vector<PointXYZI> points;
  for (int i = 0; i < 5000; ++i) {
    points.push_back({static_cast<float>(i % 70) - 5.0f, static_cast<float>(i / 70) - 5.0f, 0.0f, 1.0f});
  }
  std::vector<PointXYZI> global(points.size());
  std::vector<Centre> centres;
  IndexVector kept;
  CircularRoiSet circles(3.0, std::vector<Centre>{});
  RectangularRoiSet rects(3.0, 6.0, std::vector<Centre>{});
  GridFilter<CircularRoiSet> circle_grid;
  GridFilter<RectangularRoiSet> rect_grid;
  auto frame = [&](double s0) {
    transform_points(pose_from_xy_yaw(s0, 0, 0), points, global);
    place_centres(t, s0, 40.0, 1.5, centres);
    circles.assign(centres);
    rects.assign(centres);
    circle_grid.build(circles);
    circle_grid.filter(std::span<const PointXYZI>(global), kept);
    rect_grid.build(rects);
    rect_grid.filter(std::span<const PointXYZI>(global), kept);
    reference_filter(rects, std::span<const PointXYZI>(global), kept);
  };
  // warm-up: one pass over the frames lets every buffer reach its working size
  for (int k = 0; k < 20; ++k)
    frame(0.05 * k);
  const std::size_t before = g_allocations.load();
  for (int k = 0; k < 20; ++k)
    frame(0.05 * k);
  EXPECT_EQ(g_allocations.load() - before, 0u);
  EXPECT_GT(kept.size(), 0u);
}

}  // namespace
}  // namespace trajroi::roi
