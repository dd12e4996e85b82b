// The rings between the threads: a drop is said with the ring it happened in, the thread that
// fell behind and the buffers key that sizes the ring, as the drops start; and once more when
// the rings have gone a whole window without one, with each ring's count in all.
#include <string>

#include "health.hpp"
#include "health_format.hpp"

namespace trajroi::daemon {

namespace {

using C = Counter;

struct RingWords {
  Counter counter;
  const char* name;      // the counter's name after "ring_drops."
  const char* behind;    // who fell behind whom
  const char* capacity;  // the key that sizes it, or empty for a fixed ring
};

constexpr RingWords kRings[] = {
    {C::kRingDropsLidar, "lidar", "the processing thread fell behind the LiDAR input", "buffers.lidar_packets"},
    {C::kRingDropsGnss, "gnss", "the processing thread fell behind the GNSS port", "buffers.serial_chunks"},
    {C::kRingDropsImu, "imu", "the processing thread fell behind the IMU port", "buffers.serial_chunks"},
    {C::kRingDropsPose, "pose_input", "the processing thread fell behind the localization input",
     "buffers.serial_chunks"},
    {C::kRingDropsSweeps, "sweeps", "the publisher fell behind the processing thread", "buffers.sweeps"},
    {C::kRingDropsStatus, "status", "the publisher fell behind the status snapshots", ""},
    {C::kRingDropsTrajectory, "trajectory", "the processing thread fell behind new trajectories", ""},
    {C::kRingDropsRecord, "record", "the recorder fell behind (a slow or full disk?)", "buffers.lidar_packets"},
};

}  // namespace

void HealthMonitor::rings(const StatusSnapshot& s, std::vector<HealthLine>& out) {
  const StatusSnapshot& previous = history_[history_.size() - 2];
  std::uint64_t in_window = 0, last_second = 0;
  std::string which, totals;
  for (const RingWords& r : kRings) {
    in_window += delta(s, r.counter);
    const std::uint64_t n = s[r.counter] - previous[r.counter];
    last_second += n;
    if (n > 0) {
      which += sprintf_text("%s%s %llu (%s", which.empty() ? "" : "; ", r.name, static_cast<unsigned long long>(n),
                            r.behind);
      if (*r.capacity != '\0') which += std::string("; ") + r.capacity;
      which += ")";
    }
    if (s[r.counter] > 0)
      totals += sprintf_text("%sring_drops.%s %llu", totals.empty() ? "" : ", ", r.name,
                             static_cast<unsigned long long>(s[r.counter]));
  }
  set(kRingDrops, in_window > 0,
      sprintf_text("rings: %llu item%s dropped in the last second: ", static_cast<unsigned long long>(last_second),
                   last_second == 1 ? "" : "s") +
          which +
          ": is the CPU overloaded, or the threads' realtime priorities too low? A larger ring rides out "
          "longer stalls",
      sprintf_text("rings: no drops for %.0f s (", window_s(s)) + totals + " in all)", out);
}

}  // namespace trajroi::daemon
