// The rings between the threads: a drop is said with the ring it happened in, the thread that
// fell behind and the buffers key that sizes the ring, as the drops start; and once more when
// the rings have gone a whole window without one, with each ring's count in all.
#include <string>
#include <string_view>

#include "health.hpp"
#include "health_format.hpp"

namespace trajroi::daemon {

namespace {

using C = Counter;

// What a drop in each ring of kRingDropCounters means: who fell behind whom, and the key that
// sizes the ring (empty for a fixed ring).
struct RingWords {
  const char* behind;
  const char* capacity;
};

constexpr RingWords words(Counter c) {
  switch (c) {
    case C::kRingDropsLidar:
      return {"the processing thread fell behind the LiDAR input", "buffers.lidar_packets"};
    case C::kRingDropsGnss:
      return {"the processing thread fell behind the GNSS port", "buffers.serial_chunks"};
    case C::kRingDropsImu:
      return {"the processing thread fell behind the IMU port", "buffers.serial_chunks"};
    case C::kRingDropsPose:
      return {"the processing thread fell behind the localization input", "buffers.serial_chunks"};
    case C::kRingDropsSweeps:
      return {"the publisher fell behind the processing thread", "buffers.sweeps"};
    case C::kRingDropsStatus:
      return {"the publisher fell behind the status snapshots", ""};
    case C::kRingDropsTrajectory:
      return {"the processing thread fell behind new trajectories", ""};
    case C::kRingDropsRecord:
      return {"the recorder fell behind (a slow or full disk?)", "buffers.lidar_packets"};
    default:
      return {"", ""};
  }
}

constexpr bool every_ring_has_words() {
  for (const Counter c : kRingDropCounters)
    if (*words(c).behind == '\0') return false;
  return true;
}
static_assert(every_ring_has_words(), "a ring of kRingDropCounters without its words here");

// "sweeps" of "ring_drops.sweeps".
std::string_view ring_name(Counter c) {
  std::string_view name = counter_name(c);
  name.remove_prefix(name.find('.') + 1);
  return name;
}

}  // namespace

void HealthMonitor::rings(const StatusSnapshot& s, std::vector<HealthLine>& out) {
  const StatusSnapshot& previous = history_[history_.size() - 2];
  std::uint64_t in_window = 0, last_second = 0;
  std::string which, totals;
  for (const Counter c : kRingDropCounters) {
    in_window += delta(s, c);
    const std::uint64_t n = s[c] - previous[c];
    last_second += n;
    if (n > 0) {
      const RingWords w = words(c);
      which += (which.empty() ? "" : "; ") + std::string(ring_name(c)) + " " + std::to_string(n) + " (" + w.behind +
               (*w.capacity != '\0' ? std::string("; ") + w.capacity : std::string()) + ")";
    }
    if (s[c] > 0) totals += (totals.empty() ? "" : ", ") + std::string(counter_name(c)) + " " + std::to_string(s[c]);
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
