#pragma once

// What travels through trajroid's rings. Every slot is preallocated; producers fill in place.
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string_view>

#include "trajroi/daemon/sweep_processor.hpp"
#include "trajroi/transport/spsc_ring.hpp"

namespace trajroi::daemon {

// The order items are processed in: a global sequence taken when a producer publishes. A
// replay has a single producer, so its order (the recording's receive order) is exact.
inline std::atomic<std::uint64_t> g_sequence{0};

inline constexpr std::size_t kMaxDatagram = 1500;  // Ethernet MTU: a VLP-16 packet is 1206
inline constexpr std::size_t kMaxChunk = 1024;     // serial bytes per item (reads are split)

struct LidarItem {
  std::uint64_t seq = 0;
  std::int64_t receive_ns = 0;  // host clock of the input (recorded clock in a replay)
  std::int64_t arrival_ns = 0;  // steady clock when it entered the ring (latency)
  LidarPort port = LidarPort::kData;
  std::uint16_t size = 0;
  std::array<std::uint8_t, kMaxDatagram> bytes{};
};

struct SerialItem {
  std::uint64_t seq = 0;
  std::int64_t receive_ns = 0;
  std::int64_t arrival_ns = 0;
  std::uint16_t size = 0;
  std::array<std::uint8_t, kMaxChunk> bytes{};
};

struct TrajectoryItem {
  std::unique_ptr<ActiveTrajectory> trajectory;
};

// A named counter of the status message.
struct Counter {
  std::string_view name;
  std::uint64_t value = 0;
};
inline constexpr std::size_t kMaxCounters = 96;

// The processing thread's view, once a second, for the publisher's status message.
struct StatusSnapshot {
  std::int64_t steady_ns = 0;
  std::int32_t trajectory_id = 0;
  ProcessorCounters processor;
  std::uint64_t lidar_packets = 0, position_packets = 0, lost_packets = 0, decode_errors = 0;
  bool pose_valid = false;
  pose::PoseStatus pose_status = pose::PoseStatus::kNoGnss;
  double pose_age_s = -1.0;
  std::uint8_t fix_type = 0;
  double h_acc_m = 0.0;
  bool final = false;  // the last one: the input has ended
  std::array<Counter, kMaxCounters> counters{};
  std::size_t counter_count = 0;
  void add(std::string_view name, std::uint64_t value) noexcept {
    if (counter_count < counters.size()) counters[counter_count++] = {name, value};
  }
  // Every ring's drops ("ring_drops.*" counters) together.
  [[nodiscard]] std::uint64_t ring_drops() const noexcept {
    std::uint64_t drops = 0;
    for (std::size_t i = 0; i < counter_count; ++i) {
      if (counters[i].name.starts_with("ring_drops.")) drops += counters[i].value;
    }
    return drops;
  }
};

template <typename T>
using Ring = transport::SpscRing<T>;

}  // namespace trajroi::daemon
