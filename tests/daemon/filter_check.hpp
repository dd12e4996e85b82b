#pragma once

// What `trajroi filter` keeps of a decoded sweep placed with the pose trajroid published, and
// which decoded points a published points_t holds: the two sides of the tests that hold the
// daemon's output to the filter tool, point for point.
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "daemon_fixture.hpp"
#include "trajroi/roi/transform.hpp"

namespace daemon_test {

// The sensor pose a points_t publishes (the sweep's start).
inline Eigen::Isometry3d sensor_pose(const trajroi::points_t& m) {
  return trajroi::roi::pose_from_position_quaternion(
      Eigen::Vector3d(m.sensor_position_m[0], m.sensor_position_m[1], m.sensor_position_m[2]),
      Eigen::Quaterniond(m.sensor_orientation[0], m.sensor_orientation[1], m.sensor_orientation[2],
                         m.sensor_orientation[3]));
}

// trajroi filter's --pose argument: x,y,z,qw,qx,qy,qz printed to round-trip exactly.
inline std::string pose_argument(const Eigen::Vector3d& t, double qw, double qx, double qy, double qz) {
  char text[512];
  std::snprintf(text, sizeof text, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", t.x(), t.y(), t.z(), qw, qx, qy, qz);
  return text;
}

inline std::string pose_argument(const Eigen::Isometry3d& g) {
  const Eigen::Quaterniond q(g.rotation());
  return pose_argument(g.translation(), q.w(), q.x(), q.y(), q.z());
}

// The published numbers themselves (no rotation-matrix round trip), for bit-exact comparison.
inline std::string pose_argument(const trajroi::points_t& m) {
  return pose_argument(Eigen::Vector3d(m.sensor_position_m[0], m.sensor_position_m[1], m.sensor_position_m[2]),
                       m.sensor_orientation[0], m.sensor_orientation[1], m.sensor_orientation[2],
                       m.sensor_orientation[3]);
}

// Indices `trajroi filter` keeps of `frame` placed with the sweep's published sensor pose, or
// with `pose` (trajroi filter's --pose argument) when given.
inline std::vector<std::uint32_t> filter_keeps(const trajroi::vlp16::Frame& frame, const trajroi::points_t& m,
                                               const trajroi::roi_t& roi, const fs::path& dir,
                                               const fs::path& trajectory, std::string pose = {}) {
  if (pose.empty()) pose = pose_argument(m);
  const fs::path points = dir / ("sweep" + std::to_string(m.sweep_index) + ".csv");
  const fs::path indices = dir / ("sweep" + std::to_string(m.sweep_index) + ".idx");
  {
    std::FILE* f = std::fopen(points.c_str(), "w");
    for (const auto& p : frame.points) {
      std::fprintf(f, "%.17g,%.17g,%.17g\n", static_cast<double>(p.x), static_cast<double>(p.y),
                   static_cast<double>(p.z));
    }
    std::fclose(f);
  }
  char chain[256];
  std::snprintf(chain, sizeof chain,
                " --shape circular --diameter %.17g --spacing %.17g --start-s %.17g --look-ahead %.17g",
                2.0 * roi.radius_m, roi.spacing_m, roi.start_s_m, roi.look_ahead_m);
  const std::string cmd = std::string(TRAJROI_CLI) + " filter --trajectory " + trajectory.string() + " --points " +
                          points.string() + " --pose " + pose + chain + " --cloud-precision float --output-indices " +
                          indices.string() + " 2>/dev/null";
  EXPECT_EQ(run_command(cmd), 0) << cmd;
  std::vector<std::uint32_t> kept;
  std::istringstream in(slurp(indices));
  for (std::uint32_t i; in >> i;)
    kept.push_back(i);
  return kept;
}

// Which decoded points a points_t holds, by (firing time from the sweep's start, ring, return
// type): the decode here and the daemon's may stamp the sweep's start in different clocks (a
// pcap's record times, a live receive clock), never its firings' spacing.
inline std::vector<std::uint32_t> daemon_keeps(const trajroi::vlp16::Frame& frame, const trajroi::points_t& m) {
  std::map<std::tuple<std::int64_t, int, int>, std::uint32_t> index;
  for (std::uint32_t i = 0; i < frame.points.size(); ++i) {
    const auto& p = frame.points[i];
    index[{p.time_offset_ns, p.ring, static_cast<int>(p.return_type)}] = i;
  }
  std::vector<std::uint32_t> kept;
  for (std::size_t k = 0; k < static_cast<std::size_t>(m.num_points); ++k) {
    const auto it = index.find({m.time_offset_ns[k], m.ring[k], m.return_type[k]});
    if (it == index.end()) {
      ADD_FAILURE() << "sweep " << m.sweep_index << " point " << k << " is not a decoded point";
      return {};
    }
    kept.push_back(it->second);
  }
  return kept;
}

}  // namespace daemon_test
