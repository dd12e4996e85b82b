#include "trajroi/serial/serial_port_source.hpp"

#include <fcntl.h>
#include <libserialport.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "trajroi/host/clock.hpp"

namespace trajroi::serial {

namespace {

struct BaudRate {
  int baud;
  speed_t code;
};
constexpr std::array kBauds{BaudRate{1200, B1200},     BaudRate{2400, B2400},     BaudRate{4800, B4800},
                            BaudRate{9600, B9600},     BaudRate{19200, B19200},   BaudRate{38400, B38400},
                            BaudRate{57600, B57600},   BaudRate{115200, B115200}, BaudRate{230400, B230400},
                            BaudRate{460800, B460800}, BaudRate{921600, B921600}};

std::string sp_error_text(const char* what) {
  char* message = sp_last_error_message();
  std::string text = std::string(what) + ": " + (message != nullptr ? message : "unknown error");
  sp_free_error_message(message);
  return text;
}

std::string errno_text(const char* what) {
  return std::string(what) + ": " + std::strerror(errno);
}

}  // namespace

// One open device. read(): > 0 bytes, 0 timeout, < 0 failure (the device is gone).
class SerialPortSource::Port {
 public:
  virtual ~Port() = default;
  virtual long read(std::uint8_t* data, std::size_t size, unsigned timeout_ms) = 0;
  virtual long write(const std::uint8_t* data, std::size_t size, unsigned timeout_ms) = 0;
  [[nodiscard]] virtual Backend backend() const noexcept = 0;
};

class SerialPortSource::LibserialportPort final : public Port {
 public:
  ~LibserialportPort() override {
    if (handle_ != nullptr) {
      if (open_) sp_close(handle_);
      sp_free_port(handle_);
    }
  }
  // Returns an empty string on success, else the reason. `describable` is false when
  // libserialport does not know the device at all (then termios may).
  std::string open(const SerialPortOptions& o, bool& describable) {
    describable = sp_get_port_by_name(o.device.c_str(), &handle_) == SP_OK;
    if (!describable) return sp_error_text("libserialport cannot describe the device");
    if (sp_open(handle_, SP_MODE_READ_WRITE) != SP_OK) return sp_error_text("cannot open port");
    open_ = true;
    if (sp_set_baudrate(handle_, o.baud) != SP_OK || sp_set_bits(handle_, 8) != SP_OK ||
        sp_set_parity(handle_, SP_PARITY_NONE) != SP_OK || sp_set_stopbits(handle_, 1) != SP_OK ||
        sp_set_flowcontrol(handle_, SP_FLOWCONTROL_NONE) != SP_OK) {
      return sp_error_text("cannot configure port 8N1");
    }
    return {};
  }
  long read(std::uint8_t* data, std::size_t size, unsigned timeout_ms) override {
    return sp_blocking_read_next(handle_, data, size, timeout_ms);
  }
  long write(const std::uint8_t* data, std::size_t size, unsigned timeout_ms) override {
    return sp_blocking_write(handle_, data, size, timeout_ms);
  }
  [[nodiscard]] Backend backend() const noexcept override { return Backend::kLibserialport; }

 private:
  sp_port* handle_ = nullptr;
  bool open_ = false;
};

class SerialPortSource::TermiosPort final : public Port {
 public:
  ~TermiosPort() override {
    if (fd_ >= 0) ::close(fd_);
  }
  std::string open(const SerialPortOptions& o) {
    fd_ = ::open(o.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) return errno_text("cannot open port");
    termios tio{};
    if (tcgetattr(fd_, &tio) != 0) return errno_text("not a terminal");
    cfmakeraw(&tio);  // 8 data bits, no parity, raw bytes
    tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
    const auto rate = std::find_if(kBauds.begin(), kBauds.end(), [&](const BaudRate& b) { return b.baud == o.baud; });
    if (cfsetispeed(&tio, rate->code) != 0 || cfsetospeed(&tio, rate->code) != 0 ||
        tcsetattr(fd_, TCSANOW, &tio) != 0) {
      return errno_text("cannot configure port 8N1");
    }
    return {};
  }
  long read(std::uint8_t* data, std::size_t size, unsigned timeout_ms) override {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(timeout_ms));
    if (ready < 0) return errno == EINTR ? 0 : -1;
    if (ready == 0) return 0;
    if ((p.revents & POLLIN) == 0) return -1;  // POLLHUP / POLLERR without data: gone
    const ssize_t n = ::read(fd_, data, size);
    if (n > 0) return static_cast<long>(n);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
    return -1;  // EOF or EIO: the other end went away
  }
  long write(const std::uint8_t* data, std::size_t size, unsigned timeout_ms) override {
    std::size_t done = 0;
    const std::int64_t deadline = host::monotonic_ns() + static_cast<std::int64_t>(timeout_ms) * 1'000'000;
    while (done < size) {
      const ssize_t n = ::write(fd_, data + done, size - done);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
        continue;
      }
      if (n < 0 && errno != EAGAIN && errno != EINTR) return -1;
      const std::int64_t left_ms = (deadline - host::monotonic_ns()) / 1'000'000;
      if (left_ms <= 0) break;
      pollfd p{fd_, POLLOUT, 0};
      ::poll(&p, 1, static_cast<int>(left_ms));
    }
    return static_cast<long>(done);
  }
  [[nodiscard]] Backend backend() const noexcept override { return Backend::kTermios; }

 private:
  int fd_ = -1;
};

bool is_supported_baud(int baud) noexcept {
  return std::any_of(kBauds.begin(), kBauds.end(), [baud](const BaudRate& b) { return b.baud == baud; });
}

std::string supported_bauds_text() {
  std::string text;
  for (const BaudRate& b : kBauds) {
    if (!text.empty()) text.append(", ");
    text.append(std::to_string(b.baud));
  }
  return text;
}

SerialPortSource::SerialPortSource(SerialPortOptions options)
    : options_(std::move(options)), buffer_(options_.read_buffer_bytes), backoff_(options_.min_backoff) {
  if (options_.device.empty()) throw std::invalid_argument("serial port: no device configured");
  if (!is_supported_baud(options_.baud)) {
    throw std::invalid_argument("serial port " + options_.device + ": baud rate " + std::to_string(options_.baud) +
                                " is not one of " + supported_bauds_text());
  }
  if (options_.read_buffer_bytes == 0 || options_.min_backoff.count() <= 0 ||
      options_.max_backoff < options_.min_backoff) {
    throw std::invalid_argument("serial port " + options_.device +
                                ": buffer and backoff bounds must be positive and ordered");
  }
}

SerialPortSource::~SerialPortSource() = default;

std::string SerialPortSource::describe() const {
  return options_.device + " @ " + std::to_string(options_.baud);
}

bool SerialPortSource::is_open() const noexcept {
  return port_ != nullptr;
}

SerialPortSource::Backend SerialPortSource::backend() const noexcept {
  return port_ ? port_->backend() : Backend::kNone;
}

bool SerialPortSource::try_open() {
  std::string error;
  auto sp = std::make_unique<LibserialportPort>();
  bool describable = false;
  // A device that is not there, or not ours to open, says so with its errno (libserialport's
  // own message for these is vaguer).
  if (::access(options_.device.c_str(), R_OK | W_OK) != 0) {
    const int e = errno;
    error = std::string(std::strerror(e)) + " (errno " + std::to_string(e) + ")";
  } else {
    error = sp->open(options_, describable);
  }
  if (error.empty()) {
    port_ = std::move(sp);
  } else if (!describable && std::filesystem::exists(options_.device) &&
             ::access(options_.device.c_str(), R_OK | W_OK) == 0) {
    // A node libserialport does not know (a pseudo-terminal): termios.
    auto tty = std::make_unique<TermiosPort>();
    error = tty->open(options_);
    if (error.empty()) port_ = std::move(tty);
  }
  if (!port_) {
    // Permission bits that allow it and an open that is refused: a device cgroup (systemd's
    // DevicePolicy=closed without the device in DeviceAllow=).
    if (error.find(std::strerror(EPERM)) != std::string::npos) {
      error +=
          " (not in the device allow-list: under systemd, the unit's DeviceAllow= must list it; "
          "`trajroid --unit-drop-in` prints what the configuration needs)";
    }
    last_error_ = options_.device + ": " + error;
    ++counters_.open_failures;
    next_open_ns_ = host::monotonic_ns() + std::chrono::duration_cast<std::chrono::nanoseconds>(backoff_).count();
    backoff_ = std::min(backoff_ * 2, options_.max_backoff);
    return false;
  }
  backoff_ = options_.min_backoff;
  ++counters_.opens;
  last_error_.clear();
  return true;
}

void SerialPortSource::close_port() {
  port_.reset();
}

ReadStatus SerialPortSource::read(Chunk& chunk, std::chrono::milliseconds timeout) {
  if (!port_) {
    const std::int64_t now = host::monotonic_ns();
    if (now < next_open_ns_) {
      const auto wait = std::min<std::int64_t>(next_open_ns_ - now,
                                               std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count());
      std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
      return ReadStatus::kTimeout;
    }
    if (!try_open()) return ReadStatus::kTimeout;
  }
  const auto timeout_ms = static_cast<unsigned>(std::max<std::int64_t>(timeout.count(), 0));
  const long n = port_->read(buffer_.data(), buffer_.size(), timeout_ms);
  if (n > 0) {
    chunk.bytes = std::span<const std::uint8_t>(buffer_.data(), static_cast<std::size_t>(n));
    chunk.receive_time_ns = host::monotonic_ns();
    ++counters_.chunks;
    counters_.bytes += static_cast<std::uint64_t>(n);
    return ReadStatus::kData;
  }
  // A timeout on a device node that no longer exists is an unplug too (some USB drivers
  // report it only this way).
  if (n < 0 || !std::filesystem::exists(options_.device)) {
    last_error_ = options_.device + (n < 0 ? ": read failed (device gone)" : ": device node disappeared");
    close_port();
    ++counters_.disconnects;
    next_open_ns_ = host::monotonic_ns() + std::chrono::duration_cast<std::chrono::nanoseconds>(backoff_).count();
    return ReadStatus::kDisconnected;
  }
  return ReadStatus::kTimeout;
}

bool SerialPortSource::write(std::span<const std::uint8_t> bytes, std::chrono::milliseconds timeout) {
  if (!port_) return false;
  const auto timeout_ms = static_cast<unsigned>(std::max<std::int64_t>(timeout.count(), 0));
  const long n = port_->write(bytes.data(), bytes.size(), timeout_ms);
  return n >= 0 && static_cast<std::size_t>(n) == bytes.size();
}

}  // namespace trajroi::serial
