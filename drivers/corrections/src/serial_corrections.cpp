#include "trajroi/corrections/serial_corrections.hpp"

#include <chrono>
#include <cstdio>

#include "trajroi/serial/serial_port_source.hpp"

namespace trajroi::corrections {

SerialCorrections::SerialCorrections(const std::string& device, int baud, double stall_s, FrameSink on_frame,
                                     EventSink on_event)
    : name_("serial://" + device + "?baud=" + std::to_string(baud)),
      stall_s_(stall_s),
      on_frame_(std::move(on_frame)),
      on_event_(std::move(on_event)),
      state_("opening " + name_) {
  serial::SerialPortOptions o;
  o.device = device;
  o.baud = baud;
  o.max_backoff = std::chrono::milliseconds(1000);
  port_ = std::make_unique<serial::SerialPortSource>(std::move(o));
}

SerialCorrections::~SerialCorrections() = default;

void SerialCorrections::service(short /*revents*/, std::int64_t now_ns) {
  serial::Chunk chunk;
  const serial::ReadStatus status = port_->read(chunk, std::chrono::milliseconds(50));
  if (status == serial::ReadStatus::kData) {
    last_byte_ns_ = chunk.receive_time_ns;
    if (!streaming_) {
      streaming_ = true;
      reported_error_.clear();
      ++intake_.counters().connects;
      intake_.restart();
      state_ = "streaming from " + name_;
      if (on_event_) on_event_("receiving corrections on " + name_);
    }
    intake_.feed(chunk.bytes, [this](std::span<const std::uint8_t> frame) {
      last_frame_ns_ = last_byte_ns_;
      on_frame_(frame);
    });
    return;
  }
  const bool lost = status == serial::ReadStatus::kDisconnected ||
                    (streaming_ && now_ns - last_byte_ns_ > static_cast<std::int64_t>(stall_s_ * 1e9));
  if (streaming_ && lost) {
    streaming_ = false;
    ++intake_.counters().disconnects;
    char text[48];
    std::snprintf(text, sizeof text, "no bytes for %.1f s", stall_s_);
    const std::string why = status == serial::ReadStatus::kDisconnected ? port_->last_error() : std::string(text);
    state_ = "waiting for " + name_ + ": " + why;
    if (on_event_) on_event_(name_ + ": " + why);
  } else if (!port_->is_open() && !port_->last_error().empty() && port_->last_error() != reported_error_) {
    reported_error_ = port_->last_error();
    state_ = "cannot open " + name_ + ": " + reported_error_ + "; retrying";
    if (on_event_) on_event_(state_);
  }
}

}  // namespace trajroi::corrections
