#include "chrony_shm.hpp"

#include <sys/ipc.h>
#include <sys/shm.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>

namespace trajroi::daemon {

// The segment's layout, as ntpd's refclock_shm.c, gpsd's ntpshm.c and chrony's refclock_shm.c
// define it (struct shmTime).
struct ChronyShm::Segment {
  int mode;  // 1: the reader checks `count` before and after reading
  volatile int count;
  time_t clock_sec;  // the true time (here: GNSS UTC)
  int clock_usec;
  time_t receive_sec;  // the system clock at that instant
  int receive_usec;
  int leap;
  int precision;
  int nsamples;
  volatile int valid;
  unsigned clock_nsec;
  unsigned receive_nsec;
  int dummy[8];
};

namespace {
constexpr key_t kNtpShmKey = 0x4E545030;  // "NTP0"
}  // namespace

ChronyShm::~ChronyShm() {
  if (segment_ != nullptr) (void)shmdt(segment_);
}

std::string ChronyShm::attach() {
  if (segment_ != nullptr) return {};
  const key_t key = kNtpShmKey + unit_;
  const int id = shmget(key, sizeof(Segment), 0);
  char key_text[16];
  std::snprintf(key_text, sizeof key_text, "0x%08X", static_cast<unsigned>(key));
  if (id < 0) {
    const int e = errno;
    if (e == ENOENT) {
      return "no shared-memory segment " + std::string(key_text) + ": is chronyd running with `refclock SHM " +
             std::to_string(unit_) + "` in its configuration (chronyd makes the segment; start it first)?";
    }
    if (e == EACCES) {
      return "segment " + std::string(key_text) +
             " is not ours to write (chronyd makes SHM 0 and 1 root-only): use "
             "`refclock SHM 2` and time.chrony_shm: 2";
    }
    if (e == EINVAL) return "segment " + std::string(key_text) + " is smaller than an NTP SHM segment: not chrony's?";
    return "segment " + std::string(key_text) + ": " + std::strerror(e);
  }
  void* at = shmat(id, nullptr, 0);
  if (at == reinterpret_cast<void*>(-1)) {
    const int e = errno;
    return "segment " + std::string(key_text) + ": cannot attach: " + std::strerror(e) +
           (e == EACCES ? " (chronyd makes SHM 0 and 1 root-only: use unit 2)" : "");
  }
  segment_ = static_cast<Segment*>(at);
  return {};
}

void ChronyShm::put(std::int64_t utc_ns, std::int64_t host_utc_ns, int precision) noexcept {
  if (segment_ == nullptr) return;
  Segment& s = *segment_;
  // Mode 1: count changes around the writing, so a reader that saw it change retries.
  s.valid = 0;
  s.count = s.count + 1;
  std::atomic_thread_fence(std::memory_order_seq_cst);
  s.mode = 1;
  const auto split = [](std::int64_t ns, time_t& sec, int& usec, unsigned& nsec) {
    std::int64_t whole = ns / 1'000'000'000;
    std::int64_t rest = ns % 1'000'000'000;
    if (rest < 0) {
      rest += 1'000'000'000;
      --whole;
    }
    sec = static_cast<time_t>(whole);
    usec = static_cast<int>(rest / 1000);
    nsec = static_cast<unsigned>(rest);
  };
  split(utc_ns, s.clock_sec, s.clock_usec, s.clock_nsec);
  split(host_utc_ns, s.receive_sec, s.receive_usec, s.receive_nsec);
  s.leap = 0;  // no warning (NAV-PVT carries no leap-second announcement)
  s.precision = precision;
  s.nsamples = 0;
  std::atomic_thread_fence(std::memory_order_seq_cst);
  s.count = s.count + 1;
  s.valid = 1;
  ++samples_;
}

}  // namespace trajroi::daemon
