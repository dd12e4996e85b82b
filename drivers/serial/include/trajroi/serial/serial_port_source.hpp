#pragma once

// A live serial port: 8N1, no flow control, the configured baud rate, opened through
// libserialport. libserialport (0.1.1, and upstream by choice) cannot open pseudo-terminals
// (socat/openpty virtual ports, often used to feed recorded streams): for a device it
// cannot describe, the port is opened with POSIX termios instead, with the same settings
// and the same read loop. backend() says which one is in use.
//
// When the device disappears (USB unplug) or cannot be opened, read() keeps trying to
// (re)open it with exponential backoff and reports kDisconnected / kTimeout; it never throws
// and never takes the process down. Every disconnect and failed open is counted.
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "trajroi/serial/byte_source.hpp"

namespace trajroi::serial {

struct SerialPortOptions {
  std::string device;  // "/dev/ttyACM0", or a udev symlink such as "/dev/gnss"
  int baud = 115200;
  std::size_t read_buffer_bytes = 4096;
  std::chrono::milliseconds min_backoff{100};
  std::chrono::milliseconds max_backoff{5000};
};

// The baud rates the port layer offers (1200 … 921600, the POSIX / Linux standard rates).
[[nodiscard]] bool is_supported_baud(int baud) noexcept;
[[nodiscard]] std::string supported_bauds_text();

class SerialPortSource final : public ByteSource {
 public:
  // Throws std::invalid_argument for an empty device, a baud rate the kernel does not offer,
  // or backoff bounds out of order. Does not open the port yet (the first read() does), so
  // a daemon can start before the receiver is plugged in.
  explicit SerialPortSource(SerialPortOptions options);
  ~SerialPortSource() override;
  SerialPortSource(const SerialPortSource&) = delete;
  SerialPortSource& operator=(const SerialPortSource&) = delete;

  ReadStatus read(Chunk& chunk, std::chrono::milliseconds timeout) override;
  [[nodiscard]] const SourceCounters& counters() const noexcept override { return counters_; }
  [[nodiscard]] std::string describe() const override;

  [[nodiscard]] bool is_open() const noexcept;
  enum class Backend : std::uint8_t { kNone, kLibserialport, kTermios };
  [[nodiscard]] Backend backend() const noexcept;
  // The last libserialport / system error, empty when none.
  [[nodiscard]] const std::string& last_error() const noexcept { return last_error_; }

  // Writes all of `bytes` (receiver configuration); false when the port is not open or the
  // write failed or timed out.
  bool write(std::span<const std::uint8_t> bytes, std::chrono::milliseconds timeout);

 private:
  bool try_open();
  void close_port();

  class Port;
  class LibserialportPort;
  class TermiosPort;
  SerialPortOptions options_;
  std::unique_ptr<Port> port_;
  std::vector<std::uint8_t> buffer_;
  std::chrono::milliseconds backoff_;
  std::int64_t next_open_ns_ = 0;
  SourceCounters counters_;
  std::string last_error_;
};

}  // namespace trajroi::serial
