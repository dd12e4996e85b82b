#include "lcm_pose_input.hpp"

#include <stdexcept>

namespace trajroi::daemon {

LcmPoseInput::LcmPoseInput(const std::string& url, std::string channel) : channel_(std::move(channel)), lcm_(url) {
  if (!lcm_.good()) throw std::runtime_error("LCM " + url + ": cannot open (pose input on " + channel_ + ")");
  lcm_.subscribeFunction(
      channel_,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmPoseInput* self) {
        if (rbuf->data_size > inputs::kMaxDatagramBytes - 8) {
          ++self->oversize_;
          return;
        }
        const std::int64_t offset = inputs::realtime_ns() - inputs::monotonic_ns();
        std::vector<std::uint8_t> bytes(8 + rbuf->data_size);
        for (int i = 0; i < 8; ++i)
          bytes[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(offset) >> (8 * i));
        const auto* data = static_cast<const std::uint8_t*>(rbuf->data);
        std::copy(data, data + rbuf->data_size, bytes.begin() + 8);
        if (self->queued_.size() == kMaxQueued) self->queued_.pop_front();
        self->queued_.push_back(std::move(bytes));
      },
      this);
}

inputs::InputSource::Next LcmPoseInput::next(inputs::InputItem& item, std::chrono::milliseconds timeout) {
  if (queued_.empty()) {
    const int r = lcm_.handleTimeout(static_cast<int>(timeout.count()));
    if (r < 0) {
      ++errors_;
      error_ = "LCM " + channel_ + ": receive failed";
      return Next::kError;
    }
    if (queued_.empty()) return Next::kTimeout;
  }
  current_ = std::move(queued_.front());
  queued_.pop_front();
  item.stream = inputs::Stream::kPose;
  item.bytes = current_;
  item.receive_ns = inputs::monotonic_ns();
  ++items_;
  return Next::kItem;
}

inputs::InputCounters LcmPoseInput::counters() const noexcept {
  inputs::InputCounters c;
  c.items = items_;
  c.errors = errors_;
  c.oversize = oversize_;
  return c;
}

}  // namespace trajroi::daemon
