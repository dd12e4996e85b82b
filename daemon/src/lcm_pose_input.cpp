#include "lcm_pose_input.hpp"

#include <poll.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "trajroi/host/clock.hpp"

namespace trajroi::daemon {

LcmPoseInput::LcmPoseInput(const std::string& url, std::string channel, const std::optional<sockaddr_in>& exclude)
    : channel_(std::move(channel)) {
  if (const std::optional<LcmGroup> group = lcm_multicast_group(url)) {
    udpm_ = std::make_unique<UdpmReceiver>(url, *group, std::vector<std::string>{channel_}, exclude);
    return;
  }
  lcm_ = std::make_unique<lcm::LCM>(url);
  if (!lcm_->good()) throw std::runtime_error("LCM " + url + ": cannot open (pose input on " + channel_ + ")");
  lcm_->subscribeFunction(
      channel_,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmPoseInput* self) {
        self->enqueue(std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size));
      },
      this);
}

void LcmPoseInput::enqueue(std::span<const std::uint8_t> message) {
  if (message.size() > inputs::kMaxDatagramBytes - 8) {
    ++oversize_;
    return;
  }
  const std::int64_t offset = host::realtime_ns() - host::monotonic_ns();
  std::vector<std::uint8_t> bytes(8 + message.size());
  for (int i = 0; i < 8; ++i)
    bytes[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(offset) >> (8 * i));
  std::copy(message.begin(), message.end(), bytes.begin() + 8);
  if (queued_.size() == kMaxQueued) queued_.pop_front();
  queued_.push_back(std::move(bytes));
}

inputs::InputSource::Next LcmPoseInput::next(inputs::InputItem& item, std::chrono::milliseconds timeout) {
  if (queued_.empty()) {
    if (udpm_) {
      pollfd p{udpm_->fd(), POLLIN, 0};
      const int r = poll(&p, 1, static_cast<int>(timeout.count()));
      if (r < 0 && errno != EINTR) {
        ++errors_;
        error_ = "LCM " + channel_ + ": receive failed: " + std::strerror(errno);
        return Next::kError;
      }
      if (r > 0) udpm_->read([this](std::string_view, std::span<const std::uint8_t> m) { enqueue(m); });
    } else if (lcm_->handleTimeout(static_cast<int>(timeout.count())) < 0) {
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
  item.receive_ns = host::monotonic_ns();
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
