#pragma once

// gnss.corrections.url lcm://CHANNEL: RTCM3 bytes in rtcm_t messages on the daemon's LCM URL
// (a base station or an NTRIP client elsewhere on the robot's network shares them). Heard on a
// UdpmReceiver for udpm:// (poll-driven like every correction source), on liblcm's descriptor
// otherwise. Messages that are not rtcm_t are counted and named once.
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>

#include "trajroi/corrections/correction_source.hpp"
#include "udpm_receiver.hpp"

namespace trajroi::daemon {

class LcmCorrections final : public corrections::CorrectionSource {
 public:
  // Throws std::runtime_error when the LCM URL cannot be opened.
  LcmCorrections(const std::string& url, std::string channel, double stall_s, FrameSink on_frame, EventSink on_event);
  ~LcmCorrections() override;

  [[nodiscard]] int fd() const noexcept override;
  [[nodiscard]] short events() const noexcept override;
  [[nodiscard]] int timeout_ms(std::int64_t now_ns) const noexcept override;
  void service(short revents, std::int64_t now_ns) override;
  [[nodiscard]] const corrections::CorrectionCounters& counters() const noexcept override { return intake_.counters(); }
  [[nodiscard]] const std::string& state() const noexcept override { return state_; }
  [[nodiscard]] bool streaming() const noexcept override { return streaming_; }
  [[nodiscard]] std::int64_t last_frame_ns() const noexcept override { return last_frame_ns_; }
  [[nodiscard]] std::uint64_t not_rtcm_messages() const noexcept { return not_rtcm_; }

 private:
  void on_message(std::span<const std::uint8_t> payload, std::int64_t now_ns);

  std::string channel_;
  double stall_s_;
  FrameSink on_frame_;
  EventSink on_event_;
  std::unique_ptr<UdpmReceiver> udpm_;
  std::unique_ptr<lcm::LCM> lcm_;
  corrections::Rtcm3Intake intake_;
  std::string state_;
  std::string sender_;  // rtcm_t.source of the newest message
  bool streaming_ = false;
  std::int64_t last_message_ns_ = 0, last_frame_ns_ = 0, now_ns_ = 0;
  std::uint64_t not_rtcm_ = 0;
};

}  // namespace trajroi::daemon
