#pragma once

// RTK corrections from a radio's serial port (serial:///dev/ttyUSB1?baud=57600): a base
// station's RTCM3 over a telemetry radio. The port is opened, lost and reopened as the GNSS
// port is (serial::SerialPortSource); each service() reads for up to 50 ms (the port has no
// descriptor to poll on every backend), so the caller's loop turns at least that often.
#include <memory>
#include <string>

#include "trajroi/corrections/correction_source.hpp"

namespace trajroi::serial {
class SerialPortSource;
}  // namespace trajroi::serial

namespace trajroi::corrections {

class SerialCorrections final : public CorrectionSource {
 public:
  // Throws std::invalid_argument for a baud rate the port layer refuses.
  SerialCorrections(const std::string& device, int baud, double stall_s, FrameSink on_frame, EventSink on_event);
  ~SerialCorrections() override;

  [[nodiscard]] int fd() const noexcept override { return -1; }
  [[nodiscard]] short events() const noexcept override { return 0; }
  [[nodiscard]] int timeout_ms(std::int64_t) const noexcept override { return 0; }
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
  std::unique_ptr<serial::SerialPortSource> port_;
  Rtcm3Intake intake_;
  std::string state_, reported_error_;
  bool streaming_ = false;
  std::int64_t last_byte_ns_ = 0, last_frame_ns_ = 0;
};

}  // namespace trajroi::corrections
