#pragma once

// A ring with its producer's policy chosen once, where the ring is made, so that producers
// just push():
//   FullRing::kDrop — a full ring drops the newest item and counts it (live: a stalled
//                     consumer never holds up a sensor's thread);
//   FullRing::kWait — a full ring is waited on, calling the lane's `wait` between tries (wake
//                     the consumer, sleep briefly), until the stop flag is set; then the item
//                     is dropped and counted like any other (an as-fast-as-possible replay,
//                     whose output must not depend on the threads' timing).
// Drops are counted per kind of item (`Kinds`: e.g. one per input stream), by the lane itself.
// One producer thread and one consumer thread, as SpscRing.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>

#include "trajroi/transport/spsc_ring.hpp"

namespace trajroi::transport {

enum class FullRing : std::uint8_t { kDrop, kWait };

template <typename T, std::size_t Kinds = 1>
class RingLane {
 public:
  using Wait = std::function<void()>;

  // `stop` and whatever `wait` refers to must outlive the lane. `wait` is called only with
  // kWait, on a full ring.
  RingLane(std::size_t capacity, FullRing policy, const std::atomic<bool>& stop, Wait wait = {})
      : ring_(capacity), policy_(policy), stop_(stop), wait_(std::move(wait)) {}
  template <typename Make>
  RingLane(std::size_t capacity, Make make, FullRing policy, const std::atomic<bool>& stop, Wait wait = {})
      : ring_(capacity, std::move(make)), policy_(policy), stop_(stop), wait_(std::move(wait)) {}

  RingLane(const RingLane&) = delete;
  RingLane& operator=(const RingLane&) = delete;

  // ---- producer ----
  // Fills a slot with fill(T&) and publishes it, by the lane's policy; false when the item was
  // dropped (counted under `kind`).
  template <typename Fill>
  bool push(Fill&& fill, std::size_t kind = 0) {
    T* slot = ring_.try_claim();
    while (slot == nullptr) {
      if (policy_ == FullRing::kDrop || stop_.load(std::memory_order_relaxed)) {
        dropped_[kind].fetch_add(1, std::memory_order_relaxed);
        return false;
      }
      if (wait_) wait_();
      slot = ring_.try_claim();
    }
    fill(*slot);
    ring_.publish();
    return true;
  }

  // ---- consumer ----
  [[nodiscard]] T* front() noexcept { return ring_.front(); }
  void release() noexcept { ring_.release(); }

  // ---- any thread ----
  [[nodiscard]] FullRing policy() const noexcept { return policy_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return ring_.capacity(); }
  [[nodiscard]] std::size_t size() const noexcept { return ring_.size(); }
  [[nodiscard]] std::uint64_t dropped(std::size_t kind) const noexcept {
    return dropped_[kind].load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t dropped() const noexcept {
    std::uint64_t sum = 0;
    for (const auto& d : dropped_)
      sum += d.load(std::memory_order_relaxed);
    return sum;
  }

 private:
  SpscRing<T> ring_;
  const FullRing policy_;
  const std::atomic<bool>& stop_;
  const Wait wait_;
  std::array<std::atomic<std::uint64_t>, Kinds> dropped_{};
};

}  // namespace trajroi::transport
