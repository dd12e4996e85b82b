// The pose input the ubx and vn100 targets feed: a local frame, a small buffer and the input.
#pragma once

#include "trajroi/pose_input/pose_input.hpp"

namespace trajroi::fuzz {

struct PoseInputHarness {
  pose::GlobalFrame frame = pose::GlobalFrame::local_cartesian(pose::Geodetic{48.1351, 11.5820, 520.0});
  pose::PoseBuffer buffer{pose::PoseGate{}, Eigen::Vector3d::Zero(), 16};
  pose_input::PoseInput input{frame, pose_input::PoseInputConfig{}, buffer};
  std::int64_t t_ns = 1'000'000'000;
  // Receive time of the next piece: 10 ms after the last.
  std::int64_t next_time() noexcept { return t_ns += 10'000'000; }
};

}  // namespace trajroi::fuzz
