#pragma once

// A point cloud as the exports write it: structure of arrays, the fields of trajroid's
// points_t — position in the global frame (x east, y north, z up, m, about the configured
// origin), intensity, ring (0 = lowest laser), time after the sweep's start (s) and return type
// (1 strongest, 2 last, 3 both).
#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

#include "trajroi/points_t.hpp"

namespace trajroi::cloud_io {

struct Cloud {
  std::vector<float> x, y, z, intensity, time_s;
  std::vector<std::uint16_t> ring;
  std::vector<std::uint8_t> return_type;
  std::string comment;  // one line: where the points come from (sweep, frame)
  // UTC of time_s = 0, ns since 1970 (points_t.sweep_start_utc_ns; 0: unknown, as in a replay
  // without a PPS-locked sensor).
  std::int64_t start_utc_ns = 0;
  // The return mode the points were taken in (points_t.return_mode: 0x39 dual).
  std::uint8_t return_mode = 0;

  [[nodiscard]] std::size_t size() const noexcept { return x.size(); }
  void clear();
  void reserve(std::size_t n);
  void push(float px, float py, float pz, float i, std::uint16_t r, float t, std::uint8_t rt);
};

// The sweep's kept points (its time offsets made seconds).
[[nodiscard]] Cloud from_points(const trajroi::points_t& m);

// Sweeps gathered into one map, thinned to one point per voxel (the first to fall in it) when
// `voxel_m` > 0. Times are seconds after the first sweep's start.
class Accumulator {
 public:
  explicit Accumulator(double voxel_m) : voxel_m_(voxel_m) {}
  void add(const trajroi::points_t& m) { add(from_points(m), m.sweep_start_ns); }
  // A sweep's cloud (times after its start) that started at `sweep_start_ns` (host clock).
  void add(const Cloud& sweep, std::int64_t sweep_start_ns);
  [[nodiscard]] const Cloud& cloud() const noexcept { return cloud_; }
  [[nodiscard]] std::size_t sweeps() const noexcept { return sweeps_; }

 private:
  double voxel_m_;
  Cloud cloud_;
  std::unordered_set<std::uint64_t> occupied_;  // the voxels holding a point
  std::int64_t first_start_ns_ = 0;
  std::size_t sweeps_ = 0;
};

}  // namespace trajroi::cloud_io
