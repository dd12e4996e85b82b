// The lock-free SPSC ring: order, capacity, drop counting, and a producer and a consumer
// hammering it from two threads (run under ThreadSanitizer by the README's test command).
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include "trajroi/transport/spsc_ring.hpp"

namespace {

using trajroi::transport::SpscRing;

TEST(SpscRing, HoldsItsCapacityInOrderAndCountsWhatDidNotFit) {
  SpscRing<int> ring(5);
  EXPECT_EQ(ring.capacity(), 8u);  // rounded up to a power of two
  for (int i = 0; i < 8; ++i) {
    int* slot = ring.try_claim();
    ASSERT_NE(slot, nullptr) << i;
    *slot = i;
    ring.publish();
  }
  EXPECT_EQ(ring.try_claim(), nullptr);
  ring.count_drop();
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

TEST(SpscRing, TwoThreadsPassTwoMillionItemsWithoutLossTearingOrReordering) {
  SpscRing<Payload> ring(64);
  constexpr std::uint64_t kItems = 2'000'000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems;) {
      Payload* slot = ring.try_claim();
      if (slot == nullptr) {
        // A full ring: this test retries instead of dropping.
        std::this_thread::yield();
        continue;
      }
      slot->sequence = i;
      slot->copies.fill(i);
      ring.publish();
      ++i;
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
    for (const std::uint64_t c : item->copies) torn += c != expected ? 1 : 0;
    ring.release();
    ++expected;
  }
  producer.join();
  EXPECT_EQ(expected, kItems);
  EXPECT_EQ(torn, 0u);
}

TEST(SpscRing, AProducerThatNeverWaitsDropsTheNewestAndCountsEveryOne) {
  SpscRing<std::uint64_t> ring(16);
  constexpr std::uint64_t kItems = 200'000;
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      if (std::uint64_t* slot = ring.try_claim()) {
        *slot = i;
        ring.publish();
      } else {
        ring.count_drop();
      }
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

}  // namespace
