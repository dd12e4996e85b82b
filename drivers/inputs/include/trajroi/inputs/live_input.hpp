#pragma once

// The live inputs: the VLP-16's UDP sockets and the serial ports of the GNSS receiver and the
// IMU. Each converts its receive stamps to CLOCK_MONOTONIC here, at the edge (the kernel
// stamps datagrams with CLOCK_REALTIME; serial reads are stamped monotonic already).
#include <functional>
#include <memory>
#include <string>

#include "trajroi/inputs/input_source.hpp"
#include "trajroi/serial/serial_port_source.hpp"
#include "trajroi/vlp16/udp_source.hpp"

namespace trajroi::inputs {

class UdpInput final : public InputSource {
 public:
  // Binds the sockets (vlp16::UdpSource); throws std::runtime_error naming address and port.
  explicit UdpInput(const vlp16::UdpOptions& options);
  ~UdpInput() override;

  Next next(InputItem& item, std::chrono::milliseconds timeout) override;
  [[nodiscard]] const Notice& notice() const noexcept override { return notice_; }
  [[nodiscard]] const std::string& error() const noexcept override { return udp_->error(); }
  [[nodiscard]] InputCounters counters() const noexcept override;
  [[nodiscard]] std::string describe() const override { return describe_; }
  [[nodiscard]] const vlp16::UdpSource& udp() const noexcept { return *udp_; }

 private:
  std::unique_ptr<vlp16::UdpSource> udp_;
  std::string describe_;
  Notice notice_;
  std::uint64_t items_ = 0, oversize_ = 0, errors_ = 0;
  bool buffer_warned_ = false;
};

class SerialInput final : public InputSource {
 public:
  // `name` is "gnss" or "imu" (for notices); `stream` what its bytes are. Throws
  // std::invalid_argument for options the port layer refuses (serial::SerialPortSource).
  SerialInput(std::string name, Stream stream, serial::SerialPortOptions options);
  // Run each time the device opens (receiver configuration): its notice is said with the
  // open's. The bytes read with the opening are dropped (the hook reads the port).
  using OnOpen = std::function<Notice(serial::SerialPortSource&)>;
  void on_open(OnOpen hook) { on_open_ = std::move(hook); }
  // Run before each read, on this input's thread, while the port is open or not (RTK
  // corrections written whole between reads, never inside the configuration on_open writes).
  // With it, a read waits at most 20 ms, so that what it writes waits no longer.
  using BeforeRead = std::function<void(serial::SerialPortSource&)>;
  void before_read(BeforeRead hook) { before_read_ = std::move(hook); }
  ~SerialInput() override;

  Next next(InputItem& item, std::chrono::milliseconds timeout) override;
  [[nodiscard]] const Notice& notice() const noexcept override { return notice_; }
  [[nodiscard]] const std::string& error() const noexcept override { return port_->last_error(); }
  [[nodiscard]] InputCounters counters() const noexcept override;
  [[nodiscard]] std::string describe() const override { return port_->describe(); }

 private:
  std::string name_;
  Stream stream_;
  std::unique_ptr<serial::SerialPortSource> port_;
  std::uint64_t opens_ = 0, items_ = 0, open_failures_ = 0;
  std::string reported_error_;  // the open failure last said (said again only when it changes)
  serial::Chunk pending_;       // the last read; its bytes live in the port until the next read
  bool have_pending_ = false;   // read with the port's opening, handed out after the notice
  Notice notice_;
  OnOpen on_open_;
  BeforeRead before_read_;
};

}  // namespace trajroi::inputs
