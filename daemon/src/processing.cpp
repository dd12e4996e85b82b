// The processing thread: every lane's items in their global order through the SweepProcessor;
// finished sweeps to the publisher's ring; a status snapshot once a second and at the end.
#include <algorithm>
#include <chrono>
#include <limits>
#include <thread>

#include "chrony_shm.hpp"
#include "corrections_link.hpp"
#include "log.hpp"
#include "realtime.hpp"
#include "status.hpp"
#include "threads.hpp"

namespace trajroi::daemon {

namespace {

constexpr std::int64_t kSecond_ns = 1'000'000'000;

// Hands each finished sweep to the publisher's ring (its points exchanged with a preallocated
// slot's) with the processing time it took, and sends it on: published here, at once, when
// the publisher thread is idle (Pipeline::hand_over: no second thread to wake, which on a VM
// waits for the host to run a halted vCPU), else that thread is woken for it.
class RingSink final : public pipeline::SweepSink {
 public:
  explicit RingSink(Pipeline& pipeline) : pipeline_(pipeline) {}
  void on_sweep(pipeline::Sweep& sweep) override {
    const std::int64_t now = host::monotonic_ns();
    const auto fill = [&](pipeline::Sweep& slot) {
      slot.take(sweep);  // arrays of the same reserved capacity exchanged: no allocation
      slot.processing_ns = accumulated_ns_ + (now - packet_start_ns_);
      slot.closing_packet_start_ns = packet_start_ns_;
      slot.handed_over_ns = now;
    };
    // An as-fast-as-possible replay waits for the publisher (exact output); live drops.
    if (pipeline_.sweeps.push(fill)) {
      if (pipeline_.hand_over == nullptr || !pipeline_.hand_over->publish_here()) pipeline_.publish_wake.notify();
    }
    accumulated_ns_ = 0;
    packet_start_ns_ = host::monotonic_ns();  // the next sweep's processing starts after the publishing
  }
  void packet_started(std::int64_t now) noexcept { packet_start_ns_ = now; }
  void packet_done(std::int64_t now) noexcept { accumulated_ns_ += now - packet_start_ns_; }

 private:
  Pipeline& pipeline_;
  std::int64_t accumulated_ns_ = 0;
  std::int64_t packet_start_ns_ = 0;
};

class Processing {
 public:
  Processing(Pipeline& pipeline, pipeline::SweepProcessor& processor)
      : pipeline_(pipeline), processor_(processor), sink_(pipeline) {}

  // The lane whose front item (`front`) is oldest in the global order, or null when all are empty.
  InputLane* oldest(InputSlot*& front) noexcept {
    InputLane* best = nullptr;
    std::uint64_t best_seq = ~std::uint64_t{0};
    for (const auto& lane : pipeline_.inputs) {
      InputSlot* slot = lane->ring->front();
      if (slot != nullptr && slot->seq < best_seq) {
        best_seq = slot->seq;
        best = lane.get();
        front = slot;
      }
    }
    return best;
  }

  void handle(InputLane& lane, InputSlot& item) {
    const std::span<const std::uint8_t> bytes(item.bytes.data(), item.size);
    last_receive_ns_ = std::max(last_receive_ns_, item.receive_ns);
    const inputs::InputItem input{item.stream, bytes, item.receive_ns, item.sender, item.port};
    if (inputs::is_lidar(item.stream)) {
      const std::int64_t start = host::monotonic_ns();
      sink_.packet_started(start);
      processor_.set_input_arrival(item.arrival_ns);
      // A data packet decoded ahead by its input thread: its points are first in that lane's
      // ring of decoded packets (the tag is a guard: never another packet's points).
      vlp16::DecodedPacket* ahead = item.decoded ? lane.decoded->front() : nullptr;
      processor_.process(input, sink_, ahead != nullptr && ahead->tag == item.seq ? ahead : nullptr);
      if (ahead != nullptr) lane.decoded->release();
      sink_.packet_done(host::monotonic_ns());
    } else {
      processor_.process(input, sink_);
      if (item.stream == inputs::Stream::kGnss) new_pvt(item.receive_ns);
    }
    if (pipeline_.record) (void)pipeline_.record->push([&item](InputSlot& slot) { slot = item; });
    lane.ring->release();
  }

  // A new NAV-PVT (received at `receive_ns`): the rover's position for the corrections'
  // caster (GGA), its UTC for chrony against the raw receive time (the jitter of the serial
  // line is chrony's to filter; a mapped time would drift with the host's clock).
  void new_pvt(std::int64_t receive_ns) {
    const pose_input::PoseInput& pose = processor_.pose_input();
    if (pose.pvt_count() == pvt_seen_ || !pose.newest_pvt()) return;
    pvt_seen_ = pose.pvt_count();
    const ublox::NavPvt& pvt = *pose.newest_pvt();
    if (pipeline_.corrections) pipeline_.corrections->offer_rover(pvt);
    if (pipeline_.chrony && pvt.utc_valid()) {
      constexpr int kSerialPrecision = -7;  // ≈ 8 ms: a serial message's arrival, not a PPS edge
      pipeline_.chrony->put(pvt.utc_ns(), receive_ns + host::realtime_ns() - host::monotonic_ns(), kSerialPrecision);
    }
  }

  // time.chrony_shm: attached once chronyd has made the segment; why not, said once per reason.
  void attach_chrony(std::int64_t now) {
    if (!pipeline_.chrony || pipeline_.chrony->attached() || now < next_chrony_attach_) return;
    next_chrony_attach_ = now + 10 * kSecond_ns;
    const std::string why = pipeline_.chrony->attach();
    if (why.empty()) {
      log::info("time.chrony_shm {}: writing each NAV-PVT's UTC into chronyd's SHM {} refclock",
                pipeline_.chrony->unit(), pipeline_.chrony->unit());
    } else if (why != chrony_why_) {
      log::warn("time.chrony_shm {}: {} (tried again every 10 s)", pipeline_.chrony->unit(), why);
    }
    chrony_why_ = why;
  }

  // Trajectories offered by the publisher come in; retired ones go back to be freed there.
  void exchange_trajectories() {
    while (TrajectoryItem* t = pipeline_.trajectories_in.front()) {
      processor_.offer_trajectory(std::move(t->trajectory));
      pipeline_.trajectories_in.release();
    }
    if (auto retired = processor_.take_retired()) {
      // A full ring (the publisher has not collected 8 of them) frees it here, once.
      (void)pipeline_.trajectories_out.try_push(
          [&retired](TrajectoryItem& slot) { slot.trajectory = std::move(retired); });
    }
  }

  void snapshot(bool final) {
    const bool pushed = pipeline_.status->try_push(
        [&](StatusSnapshot& s) { fill_snapshot(processor_, pipeline_, last_receive_ns_, final, s); });
    if (pushed) pipeline_.publish_wake.notify();
  }

  void run(const ProcessingOptions& options) {
    std::int64_t next_status = host::monotonic_ns() + kSecond_ns;
    attach_chrony(host::monotonic_ns());
    if (options.live) processor_.set_host_utc_offset(host::realtime_ns() - host::monotonic_ns());
    const std::int64_t stall_at = options.stall_after_s
                                      ? host::monotonic_ns() + static_cast<std::int64_t>(*options.stall_after_s * 1e9)
                                      : std::numeric_limits<std::int64_t>::max();
    for (;;) {
      if (host::monotonic_ns() >= stall_at) {
        log::warn("fault injection: the processing thread stops making progress");
        while (!pipeline_.stop.load(std::memory_order_relaxed))
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        break;
      }
      pipeline_.processing_beat.fetch_add(1, std::memory_order_relaxed);
      exchange_trajectories();
      // The items waiting, oldest first, at most a batch before the checks above.
      int handled = 0;
      for (; handled < 256; ++handled) {
        InputSlot* front = nullptr;
        InputLane* lane = oldest(front);
        if (lane == nullptr || front == nullptr) break;
        handle(*lane, *front);
      }
      if (handled > 0 && pipeline_.record) pipeline_.record_wake.notify();

      const std::int64_t now = host::monotonic_ns();
      if (now >= next_status) {
        attach_chrony(now);
        if (options.live) processor_.set_host_utc_offset(host::realtime_ns() - host::monotonic_ns());
        snapshot(false);
        next_status += kSecond_ns;
        if (next_status < now) next_status = now + kSecond_ns;
      }
      // Stopping (SIGTERM) or at the end of a replay: what was received is processed, and the
      // sweep in progress goes out (partial): nothing already received is lost.
      const bool stopping = pipeline_.stop.load(std::memory_order_relaxed);
      if (handled == 0 && (stopping || (pipeline_.inputs_done() && pipeline_.inputs_empty()))) {
        processor_.flush(sink_);
        break;
      }
      if (handled == 0) {
        pipeline_.processing_waits.store(true);  // seen by the readers (input_thread.cpp)
        if (pipeline_.inputs_empty()) pipeline_.process_wake.wait(kIdleWait_ms);
        pipeline_.processing_waits.store(false);
      }
    }
    snapshot(true);
  }

 private:
  Pipeline& pipeline_;
  pipeline::SweepProcessor& processor_;
  RingSink sink_;
  std::int64_t last_receive_ns_ = 0;
  std::uint64_t pvt_seen_ = 0;
  std::int64_t next_chrony_attach_ = 0;
  std::string chrony_why_;
};

}  // namespace

void processing_loop(Pipeline& pipeline, pipeline::SweepProcessor& processor, const ProcessingOptions& options) {
  if (const std::string w = apply_thread_config("trajroid-proc", pipeline.config.realtime.processing); !w.empty()) {
    log::warn("{}", w);
  }
  prefault_stack();
  const std::int64_t cpu_start = host::thread_cpu_ns();
  Processing(pipeline, processor).run(options);
  pipeline.cpu_processing_ns.fetch_add(host::thread_cpu_ns() - cpu_start);
  pipeline.processing_done.store(true, std::memory_order_release);
  pipeline.publish_wake.notify();
  pipeline.record_wake.notify();
}

}  // namespace trajroi::daemon
