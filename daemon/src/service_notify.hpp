#pragma once

// systemd's notification protocol (sd_notify(3)), spoken without libsystemd: a datagram of
// newline-separated KEY=VALUE assignments ("READY=1", "STATUS=…", "WATCHDOG=1") to the
// AF_UNIX socket that $NOTIFY_SOCKET names, a path ('/…') or an abstract name ('@…'). systemd
// documents the protocol as stable and to be implemented independently; trajroid does, so
// that it does not depend on libsystemd for it.
#include <sys/types.h>

#include <cstdint>
#include <string>
#include <string_view>

namespace trajroi::daemon {

class ServiceNotifier {
 public:
  // `notify_socket`: $NOTIFY_SOCKET's value, or null (not started by a service manager:
  // every notification is then nothing to do).
  explicit ServiceNotifier(const char* notify_socket);
  ~ServiceNotifier();
  ServiceNotifier(const ServiceNotifier&) = delete;
  ServiceNotifier& operator=(const ServiceNotifier&) = delete;

  // Sends `state` (safe from any thread). False when there is no socket to send to or the
  // send failed; problem() then says why, when there was a socket.
  bool notify(std::string_view state) const noexcept;
  // Why notifications cannot be sent ("" when they can, or when none are asked for).
  [[nodiscard]] const std::string& problem() const noexcept { return problem_; }

 private:
  int fd_ = -1;
  std::string address_;  // sockaddr_un's sun_path, its leading NUL for an abstract name
  std::string problem_;
};

// The process's notifier, from $NOTIFY_SOCKET at its first use.
const ServiceNotifier& service_notifier();
// sd_notify(0, state): sends to the service manager, if any.
inline bool notify_service(std::string_view state) noexcept {
  return service_notifier().notify(state);
}

// The watchdog interval the service manager asks of this process, in µs, or 0 (none):
// $WATCHDOG_USEC when $WATCHDOG_PID is absent or `self` (sd_watchdog_enabled(3)'s rules);
// a value that is not a positive decimal number is none.
std::uint64_t watchdog_usec(const char* usec, const char* pid, pid_t self) noexcept;
// The same from this process's environment.
std::uint64_t watchdog_usec() noexcept;

}  // namespace trajroi::daemon
