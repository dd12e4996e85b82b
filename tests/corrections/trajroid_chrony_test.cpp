// time.chrony_shm against a real chronyd (Debian chrony) in -Q mode (it measures, prints the
// offset and never sets the clock): trajroid reads a real ZED-F9R log from a pseudo-terminal at
// its recorded pace and writes each NAV-PVT's UTC into the SHM refclock chronyd made. The
// offset chronyd prints must be the one trajroid's status reports (host − GNSS UTC: years,
// since the log was recorded then), so the samples are the log's time, not made up. In a
// private IPC namespace when the test may make one (root), so no other chronyd is touched.
#include <sched.h>
#include <sys/ipc.h>
#include <sys/shm.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <regex>

#include "daemon_fixture.hpp"
#include "pty_receiver.hpp"
#include "test_data.hpp"

namespace {

using namespace trajroi;
using namespace trajroi::corrections_test;
using daemon_test::Child;
using daemon_test::counter;
using daemon_test::Listener;
namespace fs = std::filesystem;

constexpr int kUnit = 13;
constexpr key_t kKey = 0x4E545030 + kUnit;
const std::string kChronyTime = "time:\n  chrony_shm: 13\n";

// chronyd's path: in /usr/sbin, which a test's PATH may leave out.
std::string chronyd_path() {
  for (const char* dir : {"/usr/sbin", "/usr/bin", "/sbin", "/usr/local/sbin"})
    if (fs::exists(fs::path(dir) / "chronyd")) return (fs::path(dir) / "chronyd").string();
  return {};
}

bool segment_exists() {
  return shmget(kKey, 0, 0) >= 0;
}

TEST(TrajroidChrony, ChronydReadsTheGnssTimeTrajroidWrites) {
  const std::string chronyd_program = chronyd_path();
  if (chronyd_program.empty()) {
    const char* ci = std::getenv("CI");
    if (ci != nullptr && std::string(ci) == "true") FAIL() << "chronyd (Debian chrony) missing under CI";
    GTEST_SKIP() << "chronyd not installed (Debian chrony; scripts/install-deps.sh installs it)";
  }
  TRAJROI_REQUIRE_DATA(rover_path, "ublox/gpsd/ublox-zed-f9r.log");
  if (unshare(CLONE_NEWIPC) != 0) std::cerr << "no private IPC namespace (not root): SHM unit 13 of this host\n";
  ASSERT_FALSE(segment_exists()) << "SHM unit 13 is in use";

  const fs::path dir = fs::path(::testing::TempDir()) / ("chrony_" + std::to_string(getpid()));
  fs::create_directories(dir);
  // chronyd makes the segment (writable by trajroid's dynamic user: perm=0666, as docs/time.md says).
  std::ofstream(dir / "chrony.conf") << "refclock SHM " << kUnit << ":perm=0666 refid GNSS poll 0 filter 3\n"
                                     << "pidfile " << (dir / "chronyd.pid").string() << "\n";
  const fs::path chrony_log = dir / "chronyd.log";
  Child chronyd(chronyd_program, {"-Q", "-d", "-t", "40", "-u", "root", "-f", (dir / "chrony.conf").string()},
                chrony_log);
  for (int i = 0; i < 100 && !segment_exists(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_TRUE(segment_exists()) << daemon_test::slurp(chrony_log);

  Receiver rx(trajroi::test::read_file(rover_path), std::chrono::milliseconds(1000));
  const std::string prefix = "CHRONY";
  const fs::path run = write_rover_config(prefix, rx.path(), "  configure: false\n", "", kChronyTime);
  Listener listener(prefix);
  const fs::path log = run / "trajroid.log";
  Child trajroid(trajroid_args(run), log);
  ASSERT_TRUE(log_says(log, "writing each NAV-PVT's UTC into chronyd's SHM 13")) << daemon_test::slurp(log);

  // chronyd -Q exits once it has a measurement: "System clock wrong by X seconds (ignored)".
  ASSERT_EQ(chronyd.wait(std::chrono::seconds(45)), 0) << daemon_test::slurp(chrony_log);
  const std::string said = daemon_test::slurp(chrony_log);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(said, m, std::regex(R"(System clock wrong by (-?[0-9.]+) seconds)"))) << said;
  const double chrony_offset = std::stod(m[1].str());  // GNSS − host: the correction chronyd would make

  ASSERT_TRUE(listener.wait_for(
      [&] {
        return !listener.statuses.empty() && std::isfinite(listener.statuses.back().host_minus_gnss_utc_s) &&
               counter(listener.statuses.back(), "time.chrony_samples") >= 3;
      },
      std::chrono::seconds(5)));
  {
    const std::lock_guard lock(listener.mutex);
    const double host_minus_gnss = listener.statuses.back().host_minus_gnss_utc_s;
    EXPECT_GT(std::abs(host_minus_gnss), 86400.0);  // the log is from another day: not the host's own time
    // trajroid's status maps each epoch at the least latency seen; chronyd averages the raw
    // receive times of its last samples, which a shared host can delay by tens of milliseconds
    // (trajroi machine has seen threads held off 15–50 ms; 55 ms apart under ASan once). The
    // log's epochs are 1 s apart, so a wrong epoch, leap second or time zone is ≥ 1 s off:
    // within a quarter of an epoch, the two agree on which instant each NAV-PVT is.
    EXPECT_NEAR(chrony_offset, -host_minus_gnss, 0.25) << said;
    std::cout << std::fixed << std::setprecision(4) << "chronyd: system clock wrong by " << chrony_offset
              << " s; trajroid: host − GNSS UTC " << host_minus_gnss << " s\n";
  }
  trajroid.signal(SIGTERM);
  EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0) << daemon_test::slurp(log);
  fs::remove_all(dir);
  fs::remove_all(run);
}

// Without chronyd's segment: named with what to do, retried, and trajroid runs on.
TEST(TrajroidChrony, AMissingSegmentIsNamedAndTheDaemonRunsOn) {
  TRAJROI_REQUIRE_DATA(rover_path, "ublox/gpsd/ublox-zed-f9r.log");
  if (unshare(CLONE_NEWIPC) != 0) std::cerr << "no private IPC namespace (not root): SHM unit 13 of this host\n";
  if (segment_exists()) GTEST_SKIP() << "SHM unit 13 exists on this host";
  Receiver rx(trajroi::test::read_file(rover_path), std::chrono::milliseconds(1000));
  const fs::path dir = write_rover_config("NOSHM", rx.path(), "  configure: false\n", "", kChronyTime);
  const fs::path log = dir / "trajroid.log";
  Child trajroid(trajroid_args(dir), log);
  EXPECT_TRUE(log_says(log,
                       "time.chrony_shm 13: no shared-memory segment 0x4E54503D: is chronyd running with `refclock "
                       "SHM 13` in its configuration"))
      << daemon_test::slurp(log);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  EXPECT_TRUE(trajroid.running()) << daemon_test::slurp(log);
  trajroid.signal(SIGTERM);
  EXPECT_EQ(trajroid.wait(std::chrono::seconds(10)), 0) << daemon_test::slurp(log);
  fs::remove_all(dir);
}

}  // namespace
