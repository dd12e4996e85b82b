#pragma once

// The trajectory file: one waypoint per line, either global-frame metres ("x,y") or WGS-84
// degrees ("lat,lon"), converted into the global frame about the configured origin. The
// file declares its coordinates with a first line `x,y` or `lat,lon` (a CSV header);
// without one, trajectory.coordinates says. A global_xy file whose every waypoint lies
// within a degree of the origin's latitude and longitude is refused: those are degrees read
// as metres.
#include <filesystem>
#include <memory>
#include <string_view>

#include "trajroi/daemon/config.hpp"
#include "trajroi/pipeline/sweep.hpp"

namespace trajroi::daemon {

struct TrajectorySource {
  std::filesystem::path file;
  TrajectoryCoordinates coordinates = TrajectoryCoordinates::kGlobalXy;
  pose::Geodetic origin;
  [[nodiscard]] static TrajectorySource from(const DaemonConfig& config) {
    return {config.trajectory_file, config.trajectory_coordinates, config.origin};
  }
};

// Reads and checks. Throws (roi::TrajectoryError, std::runtime_error) naming the file, the
// line and the value.
[[nodiscard]] std::unique_ptr<pipeline::ActiveTrajectory> load_trajectory(const TrajectorySource& source);
[[nodiscard]] roi::Trajectory parse_trajectory(std::string_view text, const TrajectorySource& source);

}  // namespace trajroi::daemon
