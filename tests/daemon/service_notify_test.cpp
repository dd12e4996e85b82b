// systemd's notification protocol as trajroid speaks it without libsystemd: the datagram
// reaches a socket named by a path or by an abstract name, a bad $NOTIFY_SOCKET is said, and
// the watchdog interval follows sd_watchdog_enabled(3)'s rules. (The whole service under a
// real systemd: tests/systemd/service_test.sh; a path socket played by a test:
// daemon_watchdog_test.cpp.)
#include "service_notify.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "notify_socket.hpp"

namespace {

using trajroi::daemon::ServiceNotifier;
using trajroi::daemon::watchdog_usec;

using test_notify::NotifySocket;
constexpr auto kWait = std::chrono::seconds(1);

TEST(ServiceNotify, TheStateReachesASocketNamedByAPath) {
  const std::string path = ::testing::TempDir() + "trajroi_notify_test_" + std::to_string(getpid()) + ".sock";
  NotifySocket receiver(path, kWait);
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
  NotifySocket receiver(name, kWait);
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
  const std::string nobody_path = ::testing::TempDir() + "trajroi_notify_nobody_" + std::to_string(getpid()) + ".sock";
  const ServiceNotifier nobody(nobody_path.c_str());
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
