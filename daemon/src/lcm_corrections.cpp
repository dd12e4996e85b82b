#include "lcm_corrections.hpp"

#include <poll.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "trajroi/rtcm_t.hpp"

namespace trajroi::daemon {

LcmCorrections::LcmCorrections(const std::string& url, std::string channel, double stall_s, FrameSink on_frame,
                               EventSink on_event)
    : channel_(std::move(channel)),
      stall_s_(stall_s),
      on_frame_(std::move(on_frame)),
      on_event_(std::move(on_event)),
      state_("waiting for rtcm_t on LCM " + channel_) {
  if (const std::optional<LcmGroup> group = lcm_multicast_group(url)) {
    udpm_ = std::make_unique<UdpmReceiver>(url, *group, std::vector<std::string>{channel_}, std::nullopt);
    return;
  }
  lcm_ = std::make_unique<lcm::LCM>(url);
  if (!lcm_->good()) throw std::runtime_error("LCM " + url + ": cannot open (corrections on " + channel_ + ")");
  lcm_->subscribeFunction(
      channel_,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmCorrections* self) {
        self->on_message(std::span(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size), self->now_ns_);
      },
      this);
}

LcmCorrections::~LcmCorrections() = default;

int LcmCorrections::fd() const noexcept {
  return udpm_ ? udpm_->fd() : lcm_->getFileno();
}

short LcmCorrections::events() const noexcept {
  return POLLIN;
}

int LcmCorrections::timeout_ms(std::int64_t now_ns) const noexcept {
  if (!streaming_) return 1000;
  const auto stall_at = last_message_ns_ + static_cast<std::int64_t>(stall_s_ * 1e9);
  return static_cast<int>(std::max<std::int64_t>(0, (stall_at - now_ns + 999'999) / 1'000'000));
}

void LcmCorrections::on_message(std::span<const std::uint8_t> payload, std::int64_t now_ns) {
  trajroi::rtcm_t m;
  if (m.decode(payload.data(), 0, static_cast<int>(payload.size())) < 0 || m.num_bytes < 0 ||
      static_cast<std::size_t>(m.num_bytes) != m.data.size()) {
    if (not_rtcm_++ == 0 && on_event_) {
      on_event_("LCM " + channel_ + ": a message of " + std::to_string(payload.size()) +
                " bytes is not an rtcm_t (another type on this channel?): not used (counted)");
    }
    return;
  }
  last_message_ns_ = now_ns;
  if (!streaming_ || m.source != sender_) {
    sender_ = m.source;
    if (!streaming_) {
      streaming_ = true;
      ++intake_.counters().connects;
      intake_.restart();
    }
    state_ = "streaming from LCM " + channel_ + (sender_.empty() ? "" : " (" + sender_ + ")");
    if (on_event_) on_event_("receiving corrections on LCM " + channel_ + (sender_.empty() ? "" : " from " + sender_));
  }
  intake_.feed(std::span<const std::uint8_t>(m.data.data(), m.data.size()),
               [this, now_ns](std::span<const std::uint8_t> frame) {
                 last_frame_ns_ = now_ns;
                 on_frame_(frame);
               });
}

void LcmCorrections::service(short revents, std::int64_t now_ns) {
  if ((revents & POLLIN) != 0) {
    if (udpm_) {
      udpm_->read([this, now_ns](std::string_view, std::span<const std::uint8_t> m) { on_message(m, now_ns); });
    } else {
      now_ns_ = now_ns;
      (void)lcm_->handleTimeout(0);
    }
  }
  if (streaming_ && now_ns - last_message_ns_ > static_cast<std::int64_t>(stall_s_ * 1e9)) {
    streaming_ = false;
    ++intake_.counters().disconnects;
    char text[64];
    std::snprintf(text, sizeof text, "no rtcm_t for %.1f s", stall_s_);
    state_ = "waiting for rtcm_t on LCM " + channel_ + ": " + text;
    if (on_event_) on_event_("LCM " + channel_ + ": " + text);
  }
}

}  // namespace trajroi::daemon
