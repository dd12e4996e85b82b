#pragma once

// RTK corrections sent as UDP datagrams to a local port (udp://[address]:port): a base station
// or a radio bridge on the robot's network (str2str -out udp://robot:port). The datagrams are
// one stream of RTCM3 bytes (a frame may span datagrams). Silence for stall_s is said once
// ("no datagram for 10.0 s") and the stream's return again.
#include <string>

#include "trajroi/corrections/correction_source.hpp"

namespace trajroi::corrections {

class UdpCorrections final : public CorrectionSource {
 public:
  // Binds the port; throws std::runtime_error naming the address, the port and the reason.
  UdpCorrections(const std::string& bind_address, std::uint16_t port, double stall_s, FrameSink on_frame,
                 EventSink on_event);
  ~UdpCorrections() override;
  UdpCorrections(const UdpCorrections&) = delete;
  UdpCorrections& operator=(const UdpCorrections&) = delete;

  [[nodiscard]] int fd() const noexcept override { return fd_; }
  [[nodiscard]] short events() const noexcept override;
  [[nodiscard]] int timeout_ms(std::int64_t now_ns) const noexcept override;
  void service(short revents, std::int64_t now_ns) override;
  [[nodiscard]] const CorrectionCounters& counters() const noexcept override { return intake_.counters(); }
  [[nodiscard]] const std::string& state() const noexcept override { return state_; }
  [[nodiscard]] bool streaming() const noexcept override { return streaming_; }
  [[nodiscard]] std::int64_t last_frame_ns() const noexcept override { return last_frame_ns_; }

 private:
  std::string name_;
  double stall_s_;
  FrameSink on_frame_;
  EventSink on_event_;
  int fd_ = -1;
  bool streaming_ = false;
  std::string state_;
  Rtcm3Intake intake_;
  std::int64_t last_datagram_ns_ = 0, last_frame_ns_ = 0;
};

}  // namespace trajroi::corrections
