#pragma once

// trajroid's thread loops, each in a file of its own; the wiring (trajroid.cpp) starts them.
#include <cstdint>
#include <filesystem>
#include <optional>

#include "pipeline.hpp"

namespace trajroi::pipeline {
class SweepProcessor;
}  // namespace trajroi::pipeline

namespace trajroi::daemon {

// input_thread.cpp: reads one source into its lane's ring until the stop flag or the end of a
// recording; serial reads longer than a slot are split (same receive time); a datagram longer
// than a slot is counted and dropped. Wakes the processing thread at once for a LiDAR packet
// that may close a sweep (and 5° ahead of the cut), otherwise once per batch of items (up to
// 64, or 20 ms).
void input_loop(Pipeline& pipeline, InputLane& lane);

// processing.cpp: the items of every lane in their global order through the SweepProcessor,
// finished sweeps to the publisher's ring, a status snapshot once a second and at the end.
struct ProcessingOptions {
  // Testing only (the watchdog test): after this many seconds the loop stops making progress.
  std::optional<double> stall_after_s;
  bool live = true;  // the host clock's UTC offset is the inputs' (false in a replay)
};
void processing_loop(Pipeline& pipeline, pipeline::SweepProcessor& processor, const ProcessingOptions& options);

// recorder.cpp: writes every item the processing thread handled into `dir` (lidar.pcap,
// gnss.trjb, imu.trjb: a run folder that replays to the same output).
void recorder_loop(Pipeline& pipeline, const std::filesystem::path& dir);

}  // namespace trajroi::daemon
