#pragma once

// GNSS time to chrony (time.chrony_shm: N): the NTP shared-memory refclock protocol gpsd and
// ntpd's SHM driver speak, on the segment chronyd made for `refclock SHM N` (key 0x4E545030 + N).
// trajroid never makes the segment itself: under systemd's RemoveIPC=yes one it made would go
// when it stops, leaving chronyd attached to a dead one; chronyd makes units ≥ 2 writable by
// every user (0 and 1 are root's). Written from the processing thread at each NAV-PVT.
#include <cstdint>
#include <string>

namespace trajroi::daemon {

class ChronyShm {
 public:
  explicit ChronyShm(int unit) noexcept : unit_(unit) {}
  ~ChronyShm();
  ChronyShm(const ChronyShm&) = delete;
  ChronyShm& operator=(const ChronyShm&) = delete;

  // Attaches to the segment when not yet attached; "" when attached, else why not (in words,
  // with what to do).
  [[nodiscard]] std::string attach();
  [[nodiscard]] bool attached() const noexcept { return segment_ != nullptr; }
  // One sample: the true time `utc_ns` (GNSS) was the host's CLOCK_REALTIME `host_utc_ns`.
  // `precision` is log2 of the sample's uncertainty in seconds. Nothing when not attached.
  void put(std::int64_t utc_ns, std::int64_t host_utc_ns, int precision) noexcept;
  [[nodiscard]] std::uint64_t samples() const noexcept { return samples_; }
  [[nodiscard]] int unit() const noexcept { return unit_; }

 private:
  struct Segment;
  int unit_;
  Segment* segment_ = nullptr;
  std::uint64_t samples_ = 0;
};

}  // namespace trajroi::daemon
