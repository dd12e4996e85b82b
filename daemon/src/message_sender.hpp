#pragma once

// Encodes the daemon's messages and sends them through the Outlet: a sweep's pose, ROI chain
// and points, and the status. The encoding buffers are kept and reused (the points' one made
// resident for the largest sweep at start, live).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "outlet.hpp"
#include "trajroi/daemon/config.hpp"
#include "trajroi/daemon/messages.hpp"
#include "trajroi/pipeline/sweep.hpp"

namespace trajroi::daemon {

class MessageSender {
 public:
  MessageSender(Outlet& outlet, const DaemonConfig& config);

  // The largest sweep's encoding, resident from the start (see Pipeline::exact).
  void make_resident();

  void send_pose(const pipeline::Sweep& s);
  void send_roi(const pipeline::Sweep& s);
  // The sweep's points encoded (the timing's encoding step), then sent.
  void encode_points(const pipeline::Sweep& s);
  void send_points();
  // outputs.raw_points: the sweep's decoded points before the ROI (Sweep::raw).
  void send_raw_points(const pipeline::Sweep& s);
  void send_trajectory(const pipeline::ActiveTrajectory& t);

  template <typename Message>
  void send(const std::string& channel, const Message& m) {
    const int size = m.getEncodedSize();
    if (encoded_.size() < static_cast<std::size_t>(size)) encoded_.resize(static_cast<std::size_t>(size));
    (void)m.encode(encoded_.data(), 0, size);
    outlet_.publish(channel, std::span<const std::uint8_t>(encoded_.data(), static_cast<std::size_t>(size)));
  }

 private:
  Outlet& outlet_;
  const DaemonConfig& config_;
  std::vector<std::uint8_t> encoded_;
  std::vector<std::uint8_t> points_encoded_;
  std::vector<std::uint8_t> raw_encoded_;
  trajroi::points_t points_;
  trajroi::pose_t pose_;
  trajroi::roi_t roi_;
  trajroi::trajectory_t trajectory_;
};

}  // namespace trajroi::daemon
