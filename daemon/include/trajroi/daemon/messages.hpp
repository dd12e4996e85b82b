#pragma once

// Between the daemon's values and its LCM messages (transport/lcmtypes): filling the outgoing
// messages from a Sweep (reusing their vectors), and checking an incoming trajectory.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "trajroi/daemon/config.hpp"
#include "trajroi/pipeline/sweep.hpp"
#include "trajroi/points_t.hpp"
#include "trajroi/pose/geodetic.hpp"
#include "trajroi/pose_t.hpp"
#include "trajroi/roi_t.hpp"
#include "trajroi/trajectory_t.hpp"

namespace trajroi::daemon {

// The configuration gives the pose mode and the pose source's words and fields.
void fill_pose(const pipeline::SweepHeader& sweep, const DaemonConfig& config, trajroi::pose_t& out);
void fill_points(const pipeline::Sweep& sweep, const DaemonConfig& config, trajroi::points_t& out);
// The sweep's points_t encoded (LCM's fingerprint and big-endian fields, the bytes
// points_t::encode writes for fill_points' message) into `out`, resized to the size. The
// arrays go from the sweep's vectors straight into the bytes: LCM's generated encoder swaps
// them an element at a time. `head` is scratch for the fields before the arrays.
void encode_points(const pipeline::Sweep& sweep, const DaemonConfig& config, trajroi::points_t& head,
                   std::vector<std::uint8_t>& out);
// The same with other columns under the sweep's head: the decoded points before the ROI
// (outputs.raw_points, Sweep::raw; `sensor_index` empty: all the one LiDAR's, or not told
// for several).
void encode_points(const pipeline::SweepHeader& sweep, const pipeline::PointColumns& points,
                   std::span<const std::uint8_t> sensor_index, const DaemonConfig& config, trajroi::points_t& head,
                   std::vector<std::uint8_t>& out);
// The active trajectory as published on lcm.channels.active_trajectory: its id, GLOBAL_XY.
void fill_trajectory(const pipeline::ActiveTrajectory& trajectory, trajroi::trajectory_t& out);
// The bytes a point takes in that encoding: x, y, z, time offset and one each of intensity,
// ring, return type and sensor.
inline constexpr std::size_t kEncodedBytesPerPoint = 4 * sizeof(std::uint32_t) + 4;
void fill_roi(const pipeline::Sweep& sweep, trajroi::roi_t& out);

// Why an incoming trajectory was refused (counted by reason in status_t).
enum class TrajectoryReject : std::uint8_t {
  kNone,
  kBadId,            // id ≤ 0
  kBadCoordinates,   // neither GLOBAL_XY nor LAT_LON
  kTooFewWaypoints,  // fewer than 2 (or fewer than 2 distinct)
  kTooManyWaypoints,
  kNonFinite,
  kOutOfRange,   // latitude beyond ±90°, longitude beyond ±180°
  kUndecodable,  // bytes that are not a trajectory_t
};
inline constexpr std::size_t kTrajectoryRejectCount = 8;
[[nodiscard]] std::string_view to_string(TrajectoryReject reason) noexcept;

struct TrajectoryCheck {
  std::unique_ptr<pipeline::ActiveTrajectory> trajectory;  // set when accepted
  TrajectoryReject reason = TrajectoryReject::kNone;
  std::string detail;  // for the log
};

inline constexpr std::int32_t kMaxMessageWaypoints = 100'000;

[[nodiscard]] TrajectoryCheck check_trajectory(const trajroi::trajectory_t& message, const pose::GlobalFrame& frame);

}  // namespace trajroi::daemon

namespace trajroi::daemon {

// Checks the size fields of an encoded trajectory_t before decoding it, so a hostile length
// cannot make the decoder allocate gigabytes: kNone when decoding is safe.
[[nodiscard]] TrajectoryReject precheck_trajectory_bytes(const void* data, std::size_t size) noexcept;

// Decodes and checks an encoded trajectory_t (never throws).
[[nodiscard]] TrajectoryCheck decode_trajectory(const void* data, std::size_t size, const pose::GlobalFrame& frame);

}  // namespace trajroi::daemon
