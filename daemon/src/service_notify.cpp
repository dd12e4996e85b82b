#include "service_notify.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace trajroi::daemon {
namespace {

// A positive decimal number that fits in 64 bits, or 0.
std::uint64_t parse_positive(const char* text) noexcept {
  if (text == nullptr || *text == '\0') return 0;
  std::uint64_t value = 0;
  for (const char* c = text; *c != '\0'; ++c) {
    if (*c < '0' || *c > '9') return 0;
    const auto digit = static_cast<std::uint64_t>(*c - '0');
    if (value > (UINT64_MAX - digit) / 10) return 0;
    value = value * 10 + digit;
  }
  return value;
}

}  // namespace

ServiceNotifier::ServiceNotifier(const char* notify_socket) {
  if (notify_socket == nullptr || *notify_socket == '\0') return;
  const std::string_view name(notify_socket);
  if (name.front() != '/' && name.front() != '@') {
    problem_ = "NOTIFY_SOCKET '" + std::string(name) + "': not a socket path nor an abstract name ('@…')";
    return;
  }
  if (name.size() >= sizeof(sockaddr_un::sun_path)) {
    problem_ = "NOTIFY_SOCKET '" + std::string(name) + "': longer than a socket address holds";
    return;
  }
  address_ = std::string(name);
  if (address_.front() == '@') address_.front() = '\0';  // the abstract namespace
  fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) problem_ = std::string("NOTIFY_SOCKET: socket(): ") + std::strerror(errno);
}

ServiceNotifier::~ServiceNotifier() {
  if (fd_ >= 0) close(fd_);
}

bool ServiceNotifier::notify(std::string_view state) const noexcept {
  if (fd_ < 0 || state.empty()) return false;
  sockaddr_un to{};
  to.sun_family = AF_UNIX;
  std::memcpy(to.sun_path, address_.data(), address_.size());
  const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + address_.size());
  const ssize_t sent =
      sendto(fd_, state.data(), state.size(), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&to), length);
  return sent == static_cast<ssize_t>(state.size());
}

const ServiceNotifier& service_notifier() {
  static const ServiceNotifier notifier(std::getenv("NOTIFY_SOCKET"));
  return notifier;
}

std::uint64_t watchdog_usec(const char* usec, const char* pid, pid_t self) noexcept {
  if (pid != nullptr && *pid != '\0' && parse_positive(pid) != static_cast<std::uint64_t>(self)) return 0;
  return parse_positive(usec);
}

std::uint64_t watchdog_usec() noexcept {
  return watchdog_usec(std::getenv("WATCHDOG_USEC"), std::getenv("WATCHDOG_PID"), getpid());
}

}  // namespace trajroi::daemon
