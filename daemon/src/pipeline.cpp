#include "pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "chrony_shm.hpp"
#include "corrections_link.hpp"
#include "status.hpp"

namespace trajroi::daemon {

Pipeline::Pipeline(const DaemonConfig& config_in, bool exact_in, bool recording)
    : config(config_in),
      exact(exact_in),
      sweeps(
          config_in.buffers.sweeps,
          [&config_in, exact_in] {
            pipeline::Sweep s;
            s.reserve(pipeline::sweep_points_capacity(config_in), 4096,
                      pipeline::raw_points_capacity(config_in) * config_in.lidars.size());
            if (!exact_in) s.make_resident();
            return s;
          },
          policy(), stop, wake_and_sleep(publish_wake, std::chrono::microseconds(20))),
      status(std::make_unique<Ring<StatusSnapshot>>(8)),
      trajectories_in(4),
      trajectories_out(8) {
  if (recording) {
    record = std::make_unique<Lane<InputSlot>>(config_in.buffers.lidar_packets, policy(), stop,
                                               wake_and_sleep(record_wake, std::chrono::microseconds(20)));
  }
}

Pipeline::~Pipeline() = default;

transport::FullRing Pipeline::policy() const noexcept {
  return exact ? transport::FullRing::kWait : transport::FullRing::kDrop;
}

std::function<void()> Pipeline::wake_and_sleep(const EventFd& consumer, std::chrono::microseconds sleep) {
  return [&consumer, sleep] {
    consumer.notify();
    std::this_thread::sleep_for(sleep);
  };
}

InputLane& Pipeline::add_input(std::unique_ptr<inputs::InputSource> source, std::size_t ring_capacity,
                               std::string thread_name, const ThreadConfig& thread, Lidar lidar) {
  auto lane = std::make_unique<InputLane>();
  lane->source = std::move(source);
  // An as-fast replay's full ring: the reader sleeps while the processing thread empties about
  // an eighth of it (a LiDAR packet takes it a few µs), not waking every few items to find the
  // ring full again (at 50 µs that was a fifth of the reader's CPU).
  const auto full_sleep =
      std::chrono::microseconds(std::clamp<std::int64_t>(static_cast<std::int64_t>(ring_capacity / 2), 20, 500));
  lane->ring = std::make_unique<InputRing>(ring_capacity, policy(), stop, wake_and_sleep(process_wake, full_sleep));
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
