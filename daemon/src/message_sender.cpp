#include "message_sender.hpp"

#include "trajroi/pipeline/sweep_processor.hpp"

namespace trajroi::daemon {

MessageSender::MessageSender(Outlet& outlet, const DaemonConfig& config) : outlet_(outlet), config_(config) {}

void MessageSender::make_resident() {
  // A page over for the head, whose size is that of an empty sweep's.
  daemon::encode_points(pipeline::Sweep{}, config_, points_, points_encoded_);
  points_encoded_.resize(points_encoded_.size() + 4096 +
                         pipeline::sweep_points_capacity(config_) * kEncodedBytesPerPoint);
  points_encoded_.clear();
  if (config_.outputs.raw_points) {
    raw_encoded_.resize(points_encoded_.capacity());
    raw_encoded_.clear();
  }
}

void MessageSender::send_pose(const pipeline::Sweep& s) {
  fill_pose(s, config_, pose_);
  send(config_.lcm.pose, pose_);
}

void MessageSender::send_roi(const pipeline::Sweep& s) {
  fill_roi(s, roi_);
  send(config_.lcm.roi, roi_);
}

void MessageSender::encode_points(const pipeline::Sweep& s) {
  daemon::encode_points(s, config_, points_, points_encoded_);
}

void MessageSender::send_points() {
  outlet_.publish(config_.lcm.points, points_encoded_);
}

void MessageSender::send_raw_points(const pipeline::Sweep& s) {
  daemon::encode_points(s, s.raw, s.raw_sensor_index, config_, points_, raw_encoded_);
  outlet_.publish(config_.lcm.raw_points, raw_encoded_);
}

void MessageSender::send_trajectory(const pipeline::ActiveTrajectory& t) {
  fill_trajectory(t, trajectory_);
  send(config_.lcm.active_trajectory, trajectory_);
}

}  // namespace trajroi::daemon
