#include "pipeline.hpp"

#include <time.h>

#include "status.hpp"

namespace trajroi::daemon {

std::int64_t steady_ns() noexcept {
  return inputs::monotonic_ns();
}

std::int64_t thread_cpu_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

Pipeline::Pipeline(const DaemonConfig& config_in, bool exact_in, bool recording)
    : config(config_in),
      exact(exact_in),
      sweeps(config_in.buffers.sweeps,
             [&config_in, exact_in] {
               Sweep s;
               s.reserve(config_in.buffers.max_points_per_sweep, 4096);
               if (!exact_in) s.make_resident();
               return s;
             }),
      status(std::make_unique<Ring<StatusSnapshot>>(8)),
      trajectories_in(4),
      trajectories_out(8) {
  if (recording) record = std::make_unique<Ring<InputSlot>>(config_in.buffers.lidar_packets);
}

Pipeline::~Pipeline() = default;

InputLane& Pipeline::add_input(std::unique_ptr<inputs::InputSource> source, std::size_t ring_capacity,
                               std::string thread_name, const ThreadConfig& thread, Lidar lidar) {
  auto lane = std::make_unique<InputLane>();
  lane->source = std::move(source);
  lane->ring = std::make_unique<Ring<InputSlot>>(ring_capacity);
  if (lidar == Lidar::kMayCarry) lane->decoded = std::make_unique<Ring<vlp16::DecodedPacket>>(kDecodeAhead);
  lane->thread_name = std::move(thread_name);
  lane->thread = thread;
  inputs.push_back(std::move(lane));
  return *inputs.back();
}

bool Pipeline::inputs_done() const noexcept {
  for (const auto& lane : inputs) {
    if (!lane->done.load(std::memory_order_acquire)) return false;
  }
  return true;
}

bool Pipeline::inputs_empty() const noexcept {
  for (const auto& lane : inputs) {
    if (lane->ring->size() != 0) return false;
  }
  return true;
}

}  // namespace trajroi::daemon
