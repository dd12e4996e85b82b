// systemd's notification protocol as trajroid speaks it without libsystemd: the datagram
// reaches a socket named by a path or by an abstract name, a bad $NOTIFY_SOCKET is said, and
// the watchdog interval follows sd_watchdog_enabled(3)'s rules. (The whole service under a
// real systemd: tests/systemd/service_test.sh; a path socket played by a test:
// daemon_watchdog_test.cpp.)
#include "service_notify.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>

namespace {

using trajroi::daemon::ServiceNotifier;
using trajroi::daemon::watchdog_usec;

// A datagram socket bound to `name` (a path, or '@' and an abstract name).
class Receiver {
 public:
  explicit Receiver(const std::string& name) : name_(name) {
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::memcpy(a.sun_path, name.data(), name.size());
    if (name.front() == '@') a.sun_path[0] = '\0';
    const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size());
    bound_ = fd_ >= 0 && bind(fd_, reinterpret_cast<const sockaddr*>(&a), length) == 0;
    timeval tv{1, 0};
    (void)setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~Receiver() {
    if (fd_ >= 0) close(fd_);
    if (name_.front() == '/') (void)std::remove(name_.c_str());
  }
  Receiver(const Receiver&) = delete;
  Receiver& operator=(const Receiver&) = delete;
  [[nodiscard]] bool bound() const { return bound_; }
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

TEST(ServiceNotify, TheStateReachesASocketNamedByAPath) {
  const std::string path = "/tmp/trajroi_notify_test_" + std::to_string(getpid()) + ".sock";
  Receiver receiver(path);
  ASSERT_TRUE(receiver.bound());
  const ServiceNotifier notifier(path.c_str());
  EXPECT_TRUE(notifier.problem().empty());
  EXPECT_TRUE(notifier.notify("READY=1\nSTATUS=running"));
  EXPECT_EQ(receiver.receive(), std::optional<std::string>("READY=1\nSTATUS=running"));
  EXPECT_TRUE(notifier.notify("WATCHDOG=1"));
  EXPECT_EQ(receiver.receive(), std::optional<std::string>("WATCHDOG=1"));
}

TEST(ServiceNotify, TheStateReachesASocketWithAnAbstractName) {
  const std::string name = "@trajroi/notify-test/" + std::to_string(getpid());
  Receiver receiver(name);
  ASSERT_TRUE(receiver.bound());
  const ServiceNotifier notifier(name.c_str());
  EXPECT_TRUE(notifier.notify("STATUS=tracking"));
  EXPECT_EQ(receiver.receive(), std::optional<std::string>("STATUS=tracking"));
}

TEST(ServiceNotify, WithoutASocketThereIsNothingToDoAndABadOneIsSaid) {
  const ServiceNotifier none(nullptr);
  EXPECT_FALSE(none.notify("READY=1"));
  EXPECT_TRUE(none.problem().empty());
  const ServiceNotifier empty("");
  EXPECT_TRUE(empty.problem().empty());

  const ServiceNotifier relative("run/notify");
  EXPECT_FALSE(relative.notify("READY=1"));
  EXPECT_NE(relative.problem().find("'run/notify'"), std::string::npos) << relative.problem();
  const std::string long_path = "/" + std::string(200, 'x');
  const ServiceNotifier too_long(long_path.c_str());
  EXPECT_FALSE(too_long.notify("READY=1"));
  EXPECT_NE(too_long.problem().find("longer than"), std::string::npos) << too_long.problem();
  // A socket nobody listens on: the send fails, nothing else happens.
  const ServiceNotifier nobody("/tmp/trajroi_notify_test_nobody.sock");
  EXPECT_FALSE(nobody.notify("READY=1"));
}

TEST(ServiceNotify, TheWatchdogIntervalIsForThisProcessOnly) {
  EXPECT_EQ(watchdog_usec("5000000", nullptr, 42), 5'000'000U);
  EXPECT_EQ(watchdog_usec("5000000", "", 42), 5'000'000U);
  EXPECT_EQ(watchdog_usec("5000000", "42", 42), 5'000'000U);
  EXPECT_EQ(watchdog_usec("5000000", "43", 42), 0U);  // another process's
  EXPECT_EQ(watchdog_usec(nullptr, nullptr, 42), 0U);
  EXPECT_EQ(watchdog_usec("", nullptr, 42), 0U);
  EXPECT_EQ(watchdog_usec("0", nullptr, 42), 0U);
  EXPECT_EQ(watchdog_usec("5s", nullptr, 42), 0U);
  EXPECT_EQ(watchdog_usec("-1", nullptr, 42), 0U);
  EXPECT_EQ(watchdog_usec("99999999999999999999999", nullptr, 42), 0U);
  EXPECT_EQ(watchdog_usec("18446744073709551615", nullptr, 42), UINT64_MAX);
}

}  // namespace
