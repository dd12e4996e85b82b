#pragma once

// A bounded, preallocated, lock-free ring between exactly one producer thread and one
// consumer thread (Lamport's queue with cached indices, as in rigtorp::SPSCQueue and the
// Linux kernel's kfifo). Items live in the ring: the producer fills a slot in place and
// publishes it, the consumer reads it in place and releases it, so nothing is copied twice
// and nothing is allocated after construction.
//
// The ring owns its drop policy. try_push() never blocks: on a full ring the newest item is
// dropped and counted (dropped(), readable from any thread). push_wait() is for producers that
// must not lose anything (an as-fast-as-possible replay): it waits for room, calling the
// caller's `on_full` between tries (wake the consumer, sleep), until the stop flag is set,
// when the item is dropped and counted like any other.
//
// Memory order: publish() stores the tail with release after the slot is written; the
// consumer's acquire load of the tail makes the slot's contents visible; release() stores the
// head with release so the producer's acquire load knows the slot is free again.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "trajroi/host/memory.hpp"

namespace trajroi::transport {

inline constexpr std::size_t kCacheLine = 64;

template <typename T>
class SpscRing {
 public:
  // `capacity` is rounded up to a power of two (at least 2). The slots' memory is made
  // resident in one call (host::populate), not a page fault per page, and every slot is then
  // constructed with `make()` (or value-initialised), so the steady state takes no page faults.
  explicit SpscRing(std::size_t capacity)
      : mask_(round_up(capacity) - 1), slots_(make_slots(mask_ + 1, [](void* at) { ::new (at) Slot(); })) {}
  template <typename Make>
  SpscRing(std::size_t capacity, Make make)
      : mask_(round_up(capacity) - 1), slots_(make_slots(mask_ + 1, [&make](void* at) { ::new (at) Slot{make()}; })) {}

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  [[nodiscard]] std::size_t capacity() const noexcept { return mask_ + 1; }

  // ---- producer ----
  // Fills the next free slot with fill(T&) and publishes it; false (the item dropped and
  // counted) when the ring is full.
  template <typename Fill>
  [[nodiscard]] bool try_push(Fill&& fill) noexcept(noexcept(fill(std::declval<T&>()))) {
    T* slot = try_claim();
    if (slot == nullptr) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    fill(*slot);
    publish();
    return true;
  }
  // As try_push, but a full ring is waited on: on_full() runs between tries (it should wake
  // the consumer and sleep briefly). False (dropped and counted) only once `stop` is set.
  template <typename Fill, typename OnFull>
  [[nodiscard]] bool push_wait(Fill&& fill, const std::atomic<bool>& stop, OnFull&& on_full) {
    T* slot = try_claim();
    while (slot == nullptr) {
      if (stop.load(std::memory_order_relaxed)) {
        dropped_.fetch_add(1, std::memory_order_relaxed);
        return false;
      }
      on_full();
      slot = try_claim();
    }
    fill(*slot);
    publish();
    return true;
  }

  // The primitives try_push is made of (tests use them to check the memory order).
  // The next free slot to fill, or nullptr when the ring is full.
  [[nodiscard]] T* try_claim() noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_cache_ > mask_) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail - head_cache_ > mask_) return nullptr;
    }
    return &slots_[tail & mask_].item;
  }
  // Makes the slot try_claim() returned visible to the consumer.
  void publish() noexcept { tail_.store(tail_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }

  // ---- consumer ----
  // The oldest published item, or nullptr when the ring is empty.
  [[nodiscard]] T* front() noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_cache_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head == tail_cache_) return nullptr;
    }
    return &slots_[head & mask_].item;
  }
  // Frees the slot front() returned.
  void release() noexcept { head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }

  // ---- any thread ----
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }
  // Items waiting (a snapshot; exact only from the consumer while the producer is idle).
  [[nodiscard]] std::size_t size() const noexcept {
    return tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_acquire);
  }

 private:
  static std::size_t round_up(std::size_t n) {
    if (n > (std::size_t{1} << 30)) throw std::invalid_argument("SpscRing: capacity above 2^30");
    std::size_t c = 2;
    while (c < n)
      c <<= 1;
    return c;
  }
  struct alignas(kCacheLine) Slot {
    T item;
  };
  struct DestroySlots {
    std::size_t count = 0;  // constructed
    void operator()(Slot* slots) const noexcept {
      for (std::size_t i = 0; i < count; ++i)
        slots[i].~Slot();
      ::operator delete (slots, std::align_val_t{alignof(Slot)});
    }
  };
  using Slots = std::unique_ptr<Slot[], DestroySlots>;
  // `count` slots in one resident allocation, each built by construct(address).
  template <typename Construct>
  static Slots make_slots(std::size_t count, Construct construct) {
    void* memory = ::operator new (count * sizeof(Slot), std::align_val_t{alignof(Slot)});
    host::populate(memory, count * sizeof(Slot));
    Slots slots(static_cast<Slot*>(memory), DestroySlots{});
    for (std::size_t i = 0; i < count; ++i) {
      construct(static_cast<void*>(slots.get() + i));  // a throw destroys the ones before
      slots.get_deleter().count = i + 1;
    }
    return slots;
  }

  const std::size_t mask_;
  const Slots slots_;
  // Producer's line: its index and its cached copy of the consumer's.
  alignas(kCacheLine) std::atomic<std::size_t> tail_{0};
  std::size_t head_cache_ = 0;
  // Consumer's line.
  alignas(kCacheLine) std::atomic<std::size_t> head_{0};
  std::size_t tail_cache_ = 0;
  alignas(kCacheLine) std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace trajroi::transport
