#pragma once

// The service manager's side of systemd's notification protocol, played by a test: a datagram
// socket bound to a path ('/…') or an abstract name ('@…'), as $NOTIFY_SOCKET names it.
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

namespace test_notify {

class NotifySocket {
 public:
  // `receive_timeout`: how long receive() waits for a notification.
  NotifySocket(std::string name, std::chrono::microseconds receive_timeout) : name_(std::move(name)) {
    if (name_.front() == '/') (void)std::remove(name_.c_str());
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    if (name_.size() >= sizeof a.sun_path) return;  // not bound
    std::memcpy(a.sun_path, name_.data(), name_.size());
    if (name_.front() == '@') a.sun_path[0] = '\0';  // the abstract namespace
    const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name_.size());
    bound_ = fd_ >= 0 && bind(fd_, reinterpret_cast<const sockaddr*>(&a), length) == 0;
    timeval tv{static_cast<time_t>(receive_timeout.count() / 1'000'000),
               static_cast<suseconds_t>(receive_timeout.count() % 1'000'000)};
    (void)setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~NotifySocket() {
    if (fd_ >= 0) close(fd_);
    if (name_.front() == '/') (void)std::remove(name_.c_str());
  }
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;

  [[nodiscard]] bool bound() const { return bound_; }
  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] std::string environment() const { return "NOTIFY_SOCKET=" + name_; }
  // One notification, or nothing within the receive timeout.
  std::optional<std::string> receive() {
    char buffer[4096];
    const ssize_t n = recv(fd_, buffer, sizeof buffer, 0);
    if (n <= 0) return std::nullopt;
    return std::string(buffer, static_cast<std::size_t>(n));
  }

 private:
  std::string name_;
  int fd_ = -1;
  bool bound_ = false;
};

}  // namespace test_notify
