#pragma once

// pose.source lcm: the robot's localization publishes pose_input_t; this input hears it (for a
// udpm:// URL on its own UdpmReceiver, which leaves out the daemon's own datagrams; otherwise
// on its own liblcm instance) and hands each message to the pipeline as an item (Stream::kPose) prefixed
// with the host's (CLOCK_REALTIME − CLOCK_MONOTONIC) at its receipt, so a UTC stamp is placed
// on the monotonic clock exactly as it was live, in a replay of the recording too.
#include <cstdint>
#include <deque>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "trajroi/inputs/input_source.hpp"
#include "udpm_receiver.hpp"

namespace trajroi::daemon {

class LcmPoseInput final : public inputs::InputSource {
 public:
  // Throws std::runtime_error when the LCM URL cannot be opened. `exclude`: the daemon's own
  // LCM source (UdpmOutlet::own_source()), left out on udpm://.
  LcmPoseInput(const std::string& url, std::string channel, const std::optional<sockaddr_in>& exclude = std::nullopt);

  Next next(inputs::InputItem& item, std::chrono::milliseconds timeout) override;
  [[nodiscard]] const inputs::Notice& notice() const noexcept override { return notice_; }
  [[nodiscard]] const std::string& error() const noexcept override { return error_; }
  [[nodiscard]] inputs::InputCounters counters() const noexcept override;
  [[nodiscard]] std::string describe() const override { return "LCM " + channel_ + " (pose_input_t)"; }

 private:
  static constexpr std::size_t kMaxQueued = 64;  // a burst beyond this between two reads: oldest dropped
  void enqueue(std::span<const std::uint8_t> message);

  std::string channel_;
  std::unique_ptr<UdpmReceiver> udpm_;  // udpm:// URLs
  std::unique_ptr<lcm::LCM> lcm_;       // the other providers
  std::deque<std::vector<std::uint8_t>> queued_;
  std::vector<std::uint8_t> current_;
  inputs::Notice notice_;
  std::string error_;
  std::uint64_t items_ = 0, errors_ = 0, oversize_ = 0;
};

}  // namespace trajroi::daemon
