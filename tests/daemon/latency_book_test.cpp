// A late sweep's log line says where its time went: a merged sweep that waited for another
// LiDAR's sweep names that wait first, and the processing thread only for its own.
#include "latency_book.hpp"

#include <gtest/gtest.h>

namespace {

using trajroi::daemon::SweepTiming;

TEST(SweepTiming, OneLidarsLateSweepNamesTheThreadsItWaitedFor) {
  const SweepTiming t{.index = 7,
                      .total_ms = 6.5,
                      .processing_wait_ms = 1.25,
                      .closing_ms = 0.25,
                      .publisher_wait_ms = 2.0,
                      .encoding_ms = 1.5,
                      .sending_ms = 1.5};
  EXPECT_EQ(t.describe(),
            "6.50 ms from its last packet to LCM (waiting for the processing thread 1.25, the closing packet and "
            "hand-over 0.25, waiting for the publisher 2.00, encoding 1.50, sending 1.50 ms)");
}

TEST(SweepTiming, AMergedSweepThatWaitedForAnotherLidarSaysSoFirst) {
  const SweepTiming t{.index = 25,
                      .total_ms = 100.06,
                      .merge_wait_ms = 99.5,
                      .processing_wait_ms = 0.04,
                      .closing_ms = 0.03,
                      .publisher_wait_ms = 0.32,
                      .encoding_ms = 0.13,
                      .sending_ms = 0.04};
  EXPECT_EQ(t.describe(),
            "100.06 ms from its last packet to LCM (waiting for the other LiDARs' sweeps 99.50 "
            "(lidar_merge.max_wait_s), waiting for the processing thread 0.04, the closing packet and hand-over 0.03, "
            "waiting for the publisher 0.32, encoding 0.13, sending 0.04 ms)");
}

}  // namespace
