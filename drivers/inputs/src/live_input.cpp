#include "trajroi/inputs/live_input.hpp"

#include <algorithm>

#include "trajroi/host/clock.hpp"

namespace trajroi::inputs {

// ---- UDP ------------------------------------------------------------------------------------

UdpInput::UdpInput(const vlp16::UdpOptions& options) : udp_(std::make_unique<vlp16::UdpSource>(options)) {
  describe_ = "UDP " + options.bind_address + ":" + std::to_string(udp_->data_port()) +
              " (data), :" + std::to_string(udp_->position_port()) + " (position), from " +
              (options.sensor_address.empty() ? std::string("any sender") : options.sensor_address + " only");
}

UdpInput::~UdpInput() = default;

InputCounters UdpInput::counters() const noexcept {
  InputCounters c;
  c.items = items_;
  c.oversize = oversize_;
  c.errors = errors_;
  c.rejected_sources = udp_->rejected_sources();
  c.kernel_drops = udp_->kernel_drops();
  return c;
}

UdpInput::Next UdpInput::next(InputItem& item, std::chrono::milliseconds timeout) {
  if (!buffer_warned_) {
    buffer_warned_ = true;
    if (std::string w = udp_->receive_buffer_warning(); !w.empty()) {
      notice_ = {Notice::Level::kWarning, std::move(w)};
      return Next::kNotice;
    }
  }
  vlp16::Datagram d;
  for (;;) {
    const auto r = udp_->next(d, timeout);
    if (r == vlp16::PacketSource::Next::kTimeout) return Next::kTimeout;
    if (r != vlp16::PacketSource::Next::kDatagram) {
      ++errors_;
      return Next::kError;
    }
    if (d.payload.size() > kMaxDatagramBytes) {
      ++oversize_;
      timeout = std::chrono::milliseconds(0);
      continue;
    }
    break;
  }
  // The kernel's stamp is CLOCK_REALTIME; the daemon's one time base is CLOCK_MONOTONIC.
  item.receive_ns = d.receive_time_ns - (host::realtime_ns() - host::monotonic_ns());
  item.stream = d.destination_port == udp_->position_port() ? Stream::kLidarPosition : Stream::kLidarData;
  item.bytes = d.payload;
  item.sender = d.sender;
  item.port = d.destination_port;
  ++items_;
  return Next::kItem;
}

// ---- serial ---------------------------------------------------------------------------------

SerialInput::SerialInput(std::string name, Stream stream, serial::SerialPortOptions options)
    : name_(std::move(name)), stream_(stream), port_(std::make_unique<serial::SerialPortSource>(std::move(options))) {}

SerialInput::~SerialInput() = default;

InputCounters SerialInput::counters() const noexcept {
  InputCounters c;
  c.items = items_;
  c.disconnects = port_->counters().disconnects;
  if (!port_->is_open()) c.closed_streams = static_cast<std::uint8_t>(1U << static_cast<unsigned>(stream_));
  return c;
}

SerialInput::Next SerialInput::next(InputItem& item, std::chrono::milliseconds timeout) {
  serial::ReadStatus status = serial::ReadStatus::kData;
  if (have_pending_) {
    have_pending_ = false;  // the bytes of the read that opened the port, after its notice
  } else {
    if (before_read_) {
      before_read_(*port_);
      timeout = std::min(timeout, std::chrono::milliseconds(20));
    }
    status = port_->read(pending_, timeout);
    // A device that cannot be opened (missing, not permitted) is said at once, and again
    // whenever the reason changes; the port keeps retrying (a USB receiver may appear later).
    if (port_->counters().open_failures != open_failures_) {
      open_failures_ = port_->counters().open_failures;
      if (port_->last_error() != reported_error_) {
        reported_error_ = port_->last_error();
        notice_ = {Notice::Level::kWarning, name_ + ": cannot open " + reported_error_ + "; retrying"};
        return Next::kNotice;
      }
    }
    if (port_->counters().opens != opens_) {
      reported_error_.clear();
      opens_ = port_->counters().opens;
      notice_ = {Notice::Level::kInfo,
                 name_ + ": " + port_->describe() + " open (" +
                     (port_->backend() == serial::SerialPortSource::Backend::kTermios ? "termios" : "libserialport") +
                     " backend)"};
      have_pending_ = status == serial::ReadStatus::kData;
      if (on_open_) {
        have_pending_ = false;
        const Notice configured = on_open_(*port_);
        notice_.text += "; " + configured.text;
        notice_.level = configured.level;
      }
      return Next::kNotice;
    }
  }
  switch (status) {
    case serial::ReadStatus::kData:
      item.stream = stream_;
      item.bytes = pending_.bytes;
      item.receive_ns = pending_.receive_time_ns;
      ++items_;
      return Next::kItem;
    case serial::ReadStatus::kDisconnected:
      // Rare and important: every one is said (a reopen follows within the backoff, <= 0.5 s).
      notice_ = {Notice::Level::kWarning,
                 name_ + ": " + port_->describe() + " disconnected (" + port_->last_error() + "); reopening"};
      return Next::kNotice;
    case serial::ReadStatus::kTimeout:
    case serial::ReadStatus::kEnd:
      break;
  }
  return Next::kTimeout;
}

}  // namespace trajroi::inputs
