#pragma once

// What trajroid's threads share: the rings between them, the wake-ups, the stop flag and the
// per-input counters. One Pipeline per daemon; each thread's loop (input_thread.cpp,
// processing.cpp, publisher.cpp, recorder.cpp, reload.cpp) takes it by reference, so a unit
// test drives them with a fake source and a fake outlet without the binary.
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "trajroi/daemon/config.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/input_source.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/transport/ring_lane.hpp"
#include "trajroi/transport/spsc_ring.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::daemon {

template <typename T>
using Ring = transport::SpscRing<T>;
// The rings between the threads whose policy is the pipeline's (Pipeline::exact); drops are
// counted by the lane, per input stream for the input lanes.
template <typename T, std::size_t Kinds = 1>
using Lane = transport::RingLane<T, Kinds>;

inline constexpr std::size_t kMaxItemBytes = inputs::kMaxDatagramBytes;  // a slot holds any datagram
inline constexpr int kIdleWait_ms = 100;                                 // every loop wakes at least this often
// LiDAR data packets an input thread decodes ahead of the processing thread at most (its ring
// of decoded packets, 1.4 MB) …
inline constexpr std::size_t kDecodeAhead = 128;
// … while that thread is busy and at least this many items (a quarter of a smaller ring) wait
// in its ring.
inline constexpr std::size_t kDecodeAheadBacklog = 16;

class EventFd {
 public:
  EventFd() : fd_(eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
    if (fd_ < 0) throw std::runtime_error(std::string("eventfd: ") + std::strerror(errno));
  }
  ~EventFd() { close(fd_); }
  EventFd(const EventFd&) = delete;
  EventFd& operator=(const EventFd&) = delete;
  [[nodiscard]] int fd() const noexcept { return fd_; }
  void notify() const noexcept {
    const std::uint64_t one = 1;
    (void)!write(fd_, &one, sizeof one);
  }
  void drain() const noexcept {
    std::uint64_t value = 0;
    (void)!read(fd_, &value, sizeof value);
  }
  // Waits until notified or the timeout passes.
  void wait(int timeout_ms) const noexcept {
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) > 0) drain();
  }

 private:
  int fd_;
};

// One input item in a ring slot (serial reads longer than a slot are split, same time).
struct InputSlot {
  std::uint64_t seq = 0;        // the pipeline's global order (Pipeline::sequence)
  std::int64_t receive_ns = 0;  // CLOCK_MONOTONIC of the input (as recorded in a replay)
  std::int64_t arrival_ns = 0;  // CLOCK_MONOTONIC when it entered the ring (latency)
  inputs::Stream stream = inputs::Stream::kLidarData;
  std::uint16_t size = 0;
  std::uint16_t port = 0;    // a datagram's destination port (several LiDARs tell theirs apart by it)
  std::uint64_t sender = 0;  // … and by its sender (inputs::InputItem)
  bool decoded = false;      // a LiDAR data packet whose points wait in its lane's `decoded` ring
  std::array<std::uint8_t, kMaxItemBytes> bytes{};
};

using InputRing = Lane<InputSlot, inputs::kStreamCount>;

// Datagrams on the LiDAR data port that are not VLP-16 data packets (another device, garbage;
// another Velodyne model is named by the decoder instead): counted with their sizes and first
// senders by the input thread, read by the publisher for the log. Lock-free.
struct ForeignDatagrams {
  static constexpr std::size_t kSenders = 4;
  std::atomic<std::uint64_t> count{0};
  std::atomic<std::uint32_t> min_size{~0U}, max_size{0};
  std::array<std::atomic<std::uint64_t>, kSenders> senders{};  // IPv4 << 16 | port; 0: free
  std::atomic<std::uint64_t> from_others{0};                   // from senders past the first four
  void add(std::size_t size, std::uint64_t sender) noexcept {
    count.fetch_add(1, std::memory_order_relaxed);
    const auto n = static_cast<std::uint32_t>(size);
    if (n < min_size.load(std::memory_order_relaxed)) min_size.store(n, std::memory_order_relaxed);
    if (n > max_size.load(std::memory_order_relaxed)) max_size.store(n, std::memory_order_relaxed);
    for (auto& s : senders) {  // one writer: a plain check-then-store
      const std::uint64_t known = s.load(std::memory_order_relaxed);
      if (known == sender) return;
      if (known == 0) {
        s.store(sender, std::memory_order_relaxed);
        return;
      }
    }
    from_others.fetch_add(1, std::memory_order_relaxed);
  }
};

// One input source with its reader thread's ring and what that thread counted.
struct InputLane {
  std::unique_ptr<inputs::InputSource> source;
  std::unique_ptr<InputRing> ring;  // its drops counted by stream
  // The points of the LiDAR data packets in `ring` that the input thread decoded ahead, in the
  // same order (made with the lane when its source may carry LiDAR data; else null).
  std::unique_ptr<Ring<vlp16::DecodedPacket>> decoded;
  std::string thread_name;  // "trajroid-lidar", …
  ThreadConfig thread;
  std::atomic<bool> done{false};
  // Copied from the source's counters by the reader, for the status.
  std::atomic<std::uint64_t> oversize{0}, errors{0}, disconnects{0}, rejected_sources{0}, kernel_drops{0};
  // Bit 1 << stream for each serial stream whose device is not open now (missing, refused).
  std::atomic<std::uint8_t> closed_streams{0};
  ForeignDatagrams foreign;  // the LiDAR lane's
};

struct TrajectoryItem {
  std::unique_ptr<pipeline::ActiveTrajectory> trajectory;
};

// Publishes the sweeps waiting in Pipeline::sweeps on the calling thread, unless another thread
// publishes now (then false: they wait for it). The Publisher is one (publisher.cpp).
class SweepHandOver {
 public:
  [[nodiscard]] virtual bool publish_here() = 0;

 protected:
  ~SweepHandOver() = default;
};

struct StatusSnapshot;
class CorrectionsLink;
class ChronyShm;

struct Pipeline {
  // `exact`: an as-fast-as-possible replay, where a full ring is waited on (the output is
  // the same on every run); otherwise a full ring drops the newest item and counts it.
  // Otherwise, too, the sweeps' memory is made resident at start (Sweep::make_resident, here,
  // in the processor and the publisher: about 25 MB at the default buffers, 12 ms on a VM), so
  // that the daemon's memory is flat from its first sweep and no sweep takes a page fault; in
  // an as-fast replay, a batch job whose start-up is part of its time and whose sweeps use a
  // tenth of their room, each sweep is made resident as it fills (Sweep::make_resident_to).
  Pipeline(const DaemonConfig& config, bool exact, bool record);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Adds a source and its ring (before the threads start). A source that may yield LiDAR data
  // packets gets its ring of decoded packets here, every slot's memory touched, so that the
  // first time its thread decodes ahead (a replay running behind, a flood) allocates nothing.
  enum class Lidar : bool { kNone, kMayCarry };
  InputLane& add_input(std::unique_ptr<inputs::InputSource> source, std::size_t ring_capacity, std::string thread_name,
                       const ThreadConfig& thread, Lidar lidar = Lidar::kMayCarry);
  [[nodiscard]] bool inputs_done() const noexcept;
  // kWait when exact, else kDrop: the policy of the lanes between the threads.
  [[nodiscard]] transport::FullRing policy() const noexcept;
  // A full exact lane's wait: wake its consumer, sleep.
  static std::function<void()> wake_and_sleep(const EventFd& consumer, std::chrono::microseconds sleep);
  [[nodiscard]] bool inputs_empty() const noexcept;

  const DaemonConfig& config;
  const bool exact;
  // The processor (SweepProcessor), set before the threads start: the input threads route
  // each LiDAR data packet to its sensor's lane (lane_for) and decode it ahead with that
  // lane's decoders (StreamDecoder::decoder_for), on their own core. Const calls only.
  const pipeline::SweepProcessor* processor = nullptr;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> sequence{0};
  EventFd process_wake, publish_wake, record_wake, main_wake;
  std::vector<std::unique_ptr<InputLane>> inputs;
  Lane<pipeline::Sweep> sweeps;
  // Live (not exact) with realtime.publish_from_processing: the processing thread publishes a
  // sweep it finished itself through this when the publisher thread is idle, rather than wake
  // that thread (set before the threads start; else null: the publisher thread publishes all).
  SweepHandOver* hand_over = nullptr;
  std::unique_ptr<Ring<StatusSnapshot>> status;
  Ring<TrajectoryItem> trajectories_in;     // publisher → processing
  Ring<TrajectoryItem> trajectories_out;    // processing → publisher (to free)
  std::unique_ptr<Lane<InputSlot>> record;  // processing → recorder, when recording
  std::string record_dir;                   // its folder (set before the threads start)
  // gnss.corrections on a live GNSS port (set before the threads start; else null).
  std::unique_ptr<CorrectionsLink> corrections;
  // time.chrony_shm on a live GNSS port: written by the processing thread (else null).
  std::unique_ptr<ChronyShm> chrony;
  std::atomic<bool> record_failed{false};  // the recorder stopped on an error (logged)
  std::atomic<bool> processing_done{false}, publishing_done{false};
  // The processing thread is about to wait for input, or waits: an as-fast-as-possible
  // replay's reader then wakes it at once instead of at the end of its batch.
  std::atomic<bool> processing_waits{false};
  std::atomic<std::uint64_t> processing_beat{0}, publishing_beat{0};
  // CPU time of each kind of thread, added as each ends (for the summary).
  std::atomic<std::int64_t> cpu_sources_ns{0}, cpu_processing_ns{0}, cpu_publishing_ns{0};
};

}  // namespace trajroi::daemon
