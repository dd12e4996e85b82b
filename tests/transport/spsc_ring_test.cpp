// The lock-free SPSC ring: order, capacity, drop counting, and a producer and a consumer
// hammering it from two threads (run under ThreadSanitizer by the README's test command).
#include "trajroi/transport/spsc_ring.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include "resident.hpp"
#include "trajroi/transport/ring_lane.hpp"

namespace {

using trajroi::transport::FullRing;
using trajroi::transport::RingLane;
using trajroi::transport::SpscRing;

TEST(SpscRing, HoldsItsCapacityInOrderAndCountsWhatDidNotFit) {
  SpscRing<int> ring(5);
  EXPECT_EQ(ring.capacity(), 8u);  // rounded up to a power of two
  for (int i = 0; i < 8; ++i) {
    ASSERT_TRUE(ring.try_push([i](int& slot) { slot = i; })) << i;
  }
  EXPECT_EQ(ring.try_claim(), nullptr);
  EXPECT_FALSE(ring.try_push([](int& slot) { slot = 99; }));
  EXPECT_EQ(ring.dropped(), 1u);
  EXPECT_EQ(ring.size(), 8u);
  for (int i = 0; i < 8; ++i) {
    int* item = ring.front();
    ASSERT_NE(item, nullptr);
    EXPECT_EQ(*item, i);
    ring.release();
  }
  EXPECT_EQ(ring.front(), nullptr);
  EXPECT_NE(ring.try_claim(), nullptr);  // room again
}

struct Payload {
  std::uint64_t sequence = 0;
  std::array<std::uint64_t, 15> copies{};  // every copy = sequence: a torn read shows
};

// The slots are one allocation, resident from construction (one populate, not a page fault
// a page), each built by make() or value-initialised; their items are destroyed with the ring.
TEST(SpscRing, ItsSlotsAreResidentFromConstructionAndBuiltByMake) {
  struct Big {
    std::array<std::uint8_t, 40000> bytes;  // 1 024 slots: 40 MB, a fresh mapping of its own
  };
  SpscRing<Big> ring(1024);
  for (std::size_t i = 0; i < ring.capacity(); ++i) {
    Big* slot = ring.try_claim();
    ASSERT_NE(slot, nullptr);
    ASSERT_TRUE(test_memory::resident(slot, sizeof(Big))) << "slot " << i;
    ASSERT_EQ(slot->bytes[0] + slot->bytes[sizeof slot->bytes - 1], 0) << "value-initialised";
    ring.publish();
  }
  static int alive = 0;
  struct Counted {
    int value = 0;
    explicit Counted(int v) : value(v) { ++alive; }
    Counted(Counted&& other) noexcept : value(other.value) { ++alive; }
    Counted(const Counted&) = delete;
    Counted& operator=(Counted&&) noexcept = default;
    Counted& operator=(const Counted&) = delete;
    ~Counted() { --alive; }
  };
  {
    int made = 0;
    SpscRing<Counted> counted(4, [&made] { return Counted(10 + made++); });
    EXPECT_EQ(alive, 4);
    for (int i = 0; i < 4; ++i) {
      const Counted* c = counted.try_claim();
      ASSERT_NE(c, nullptr);
      EXPECT_EQ(c->value, 10 + i);
      counted.publish();
    }
  }
  EXPECT_EQ(alive, 0);
}

TEST(SpscRing, TwoThreadsPassTwoMillionItemsWithoutLossTearingOrReordering) {
  SpscRing<Payload> ring(64);
  constexpr std::uint64_t kItems = 2'000'000;
  const std::atomic<bool> never{false};
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      // A full ring is waited on: nothing may be lost.
      const bool pushed = ring.push_wait(
          [i](Payload& slot) {
            slot.sequence = i;
            slot.copies.fill(i);
          },
          never, [] { std::this_thread::yield(); });
      if (!pushed) return;
    }
  });
  std::uint64_t expected = 0;
  std::uint64_t torn = 0;
  while (expected < kItems) {
    const Payload* item = ring.front();
    if (item == nullptr) {
      std::this_thread::yield();
      continue;
    }
    if (item->sequence != expected) break;
    for (const std::uint64_t c : item->copies)
      torn += c != expected ? 1 : 0;
    ring.release();
    ++expected;
  }
  producer.join();
  EXPECT_EQ(expected, kItems);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(ring.dropped(), 0u);
}

TEST(SpscRing, AWaitingPushGivesUpWhenStoppedAndCountsTheDrop) {
  SpscRing<int> ring(2);
  ASSERT_TRUE(ring.try_push([](int& v) { v = 1; }));
  ASSERT_TRUE(ring.try_push([](int& v) { v = 2; }));
  std::atomic<bool> stop{false};
  int waits = 0;
  const bool pushed = ring.push_wait([](int& v) { v = 3; }, stop,
                                     [&] {
                                       if (++waits == 3) stop = true;  // the consumer never comes: a stop ends the wait
                                     });
  EXPECT_FALSE(pushed);
  EXPECT_EQ(waits, 3);
  EXPECT_EQ(ring.dropped(), 1u);
  const int* oldest = ring.front();
  ASSERT_NE(oldest, nullptr);
  EXPECT_EQ(*oldest, 1);
}

TEST(SpscRing, AProducerThatNeverWaitsDropsTheNewestAndCountsEveryOne) {
  SpscRing<std::uint64_t> ring(16);
  constexpr std::uint64_t kItems = 200'000;
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      (void)ring.try_push([i](std::uint64_t& slot) { slot = i; });
    }
    done = true;
  });
  std::uint64_t received = 0, last = 0;
  bool increasing = true;
  while (!done || ring.front() != nullptr) {
    if (const std::uint64_t* item = ring.front()) {
      if (received > 0 && *item <= last) increasing = false;
      last = *item;
      ++received;
      ring.release();
    }
  }
  producer.join();
  EXPECT_TRUE(increasing);
  EXPECT_EQ(received + ring.dropped(), kItems);
}

// A lossy lane drops the newest item of a full ring and counts it under the item's kind;
// nothing it already holds is touched.
TEST(SpscRing, ALossyLaneCountsItsDropsByKind) {
  const std::atomic<bool> stop{false};
  RingLane<int, 3> lane(4, FullRing::kDrop, stop, [] { FAIL() << "a lossy lane never waits"; });
  for (int i = 0; i < 4; ++i)
    ASSERT_TRUE(lane.push([i](int& slot) { slot = i; }, 0));
  EXPECT_FALSE(lane.push([](int& slot) { slot = 90; }, 1));
  EXPECT_FALSE(lane.push([](int& slot) { slot = 91; }, 2));
  EXPECT_FALSE(lane.push([](int& slot) { slot = 92; }, 2));
  EXPECT_EQ(lane.dropped(0), 0u);
  EXPECT_EQ(lane.dropped(1), 1u);
  EXPECT_EQ(lane.dropped(2), 2u);
  EXPECT_EQ(lane.dropped(), 3u);
  for (int i = 0; i < 4; ++i) {
    const int* item = lane.front();
    ASSERT_NE(item, nullptr);
    EXPECT_EQ(*item, i);
    lane.release();
  }
  EXPECT_EQ(lane.front(), nullptr);
}

// An exact lane waits on a full ring (its wait runs between tries) until the consumer makes
// room: two threads pass every item, none dropped; once stopped, a full lane drops and counts.
TEST(SpscRing, AnExactLaneLosesNothingAndGivesUpOnlyWhenStopped) {
  std::atomic<bool> stop{false};
  std::atomic<int> waits{0};
  RingLane<int> lane(8, FullRing::kWait, stop, [&waits] {
    waits.fetch_add(1, std::memory_order_relaxed);
    std::this_thread::yield();
  });
  constexpr int kItems = 200'000;
  std::thread consumer([&lane] {
    for (int expected = 0; expected < kItems;) {
      if (int* item = lane.front()) {
        ASSERT_EQ(*item, expected);
        ++expected;
        lane.release();
      }
    }
  });
  for (int i = 0; i < kItems; ++i)
    ASSERT_TRUE(lane.push([i](int& slot) { slot = i; }));
  consumer.join();
  EXPECT_EQ(lane.dropped(), 0u);
  EXPECT_GT(waits.load(), 0) << "the producer outran an 8-slot ring at least once";
  for (int i = 0; i < 8; ++i)
    ASSERT_TRUE(lane.push([](int& slot) { slot = 0; }));
  stop.store(true);
  EXPECT_FALSE(lane.push([](int& slot) { slot = 1; }));
  EXPECT_EQ(lane.dropped(), 1u);
}

}  // namespace
