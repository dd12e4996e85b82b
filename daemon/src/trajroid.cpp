#include "trajroid.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <systemd/sd-daemon.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "items.hpp"
#include "trajroi/daemon/latency_histogram.hpp"
#include "log.hpp"
#include "realtime.hpp"
#include "trajroi/daemon/messages.hpp"
#include "trajroi/serial/byte_log.hpp"
#include "trajroi/serial/serial_port_source.hpp"
#include "trajroi/status_t.hpp"
#include "trajroi/transport/lcm_subscribe.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/udp_source.hpp"

namespace trajroi::daemon {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

constexpr std::int64_t kSecond_ns = 1'000'000'000;
constexpr int kIdleWait_ms = 100;  // every loop wakes at least this often (stop, watchdog)

std::int64_t clock_ns(clockid_t clock) noexcept {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kSecond_ns + ts.tv_nsec;
}
std::int64_t steady_ns() noexcept { return clock_ns(CLOCK_MONOTONIC); }
std::int64_t thread_cpu_ns() noexcept { return clock_ns(CLOCK_THREAD_CPUTIME_ID); }

// Sleeps to an absolute CLOCK_MONOTONIC time, waking at least every 50 ms to see `stop`.
void sleep_until_steady(std::int64_t deadline_ns, const std::atomic<bool>& stop) noexcept {
  constexpr std::int64_t kStopCheck_ns = 50'000'000;
  while (!stop.load(std::memory_order_relaxed)) {
    const std::int64_t now = steady_ns();
    if (now >= deadline_ns) return;
    const std::int64_t until = std::min(deadline_ns, now + kStopCheck_ns);
    timespec ts{static_cast<time_t>(until / 1'000'000'000), static_cast<long>(until % 1'000'000'000)};
    (void)clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
  }
}

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

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw config::ConfigError(file.string() + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::unique_ptr<ActiveTrajectory> load_trajectory(const fs::path& file) {
  return std::make_unique<ActiveTrajectory>(
      ActiveTrajectory{roi::parse_trajectory_csv(read_text(file), file.string()), 0});
}

double percentile(std::vector<double>& samples, double q) {
  if (samples.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::min(q * static_cast<double>(samples.size()), static_cast<double>(samples.size() - 1)));
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(k), samples.end());
  return samples[k];
}

class Daemon;

// Hands each finished sweep to the publisher's ring (copied into a preallocated slot).
class RingSink final : public SweepSink {
 public:
  // `wait_for_room`: an as-fast-as-possible replay waits for the publisher (exact output);
  // otherwise a full ring drops the sweep and counts it.
  RingSink(Ring<Sweep>& ring, const EventFd& wake, bool wait_for_room, const std::atomic<bool>& stop)
      : ring_(ring), wake_(wake), wait_(wait_for_room), stop_(stop) {}
  void on_sweep(const Sweep& sweep) override {
    const std::int64_t now = steady_ns();
    Sweep* slot = ring_.try_claim();
    while (slot == nullptr && wait_ && !stop_.load(std::memory_order_relaxed)) {
      std::this_thread::sleep_for(std::chrono::microseconds(20));
      slot = ring_.try_claim();
    }
    if (slot == nullptr) {
      ring_.count_drop();
    } else {
      *slot = sweep;  // vector assignment within the reserved capacity: no allocation
      slot->processing_ns = accumulated_ns_ + (now - packet_start_ns_);
      ring_.publish();
      wake_.notify();
    }
    accumulated_ns_ = 0;
    packet_start_ns_ = now;
  }
  void packet_started(std::int64_t now) noexcept { packet_start_ns_ = now; }
  void packet_done(std::int64_t now) noexcept { accumulated_ns_ += now - packet_start_ns_; }

 private:
  Ring<Sweep>& ring_;
  const EventFd& wake_;
  bool wait_;
  const std::atomic<bool>& stop_;
  std::int64_t accumulated_ns_ = 0;
  std::int64_t packet_start_ns_ = 0;
};

class Daemon {
 public:
  Daemon(const DaemonConfig& config, const RunOptions& options)
      : config_(config),
        options_(options),
        frame_(pose::GlobalFrame::local_cartesian(config.origin)),
        lidar_(config.buffers.lidar_packets),
        gnss_(config.buffers.serial_chunks),
        imu_(config.buffers.serial_chunks),
        sweeps_(config.buffers.sweeps,
                [&config] {
                  Sweep s;
                  s.reserve(config.buffers.max_points_per_sweep, 4096);
                  return s;
                }),
        status_(8),
        trajectories_in_(4),
        trajectories_out_(8),
        warn_limit_(config.logging.warning_interval_s) {}

  int run();

 private:
  void open_sources();
  void open_replay(bool first);
  void lidar_live();
  void serial_live(serial::SerialPortSource& source, Ring<SerialItem>& ring, std::atomic<bool>& done,
                   const char* name, const ThreadConfig& thread);
  void replay();
  void processing();
  void publishing(lcm::LCM& lcm);
  void recording();
  void record_to(const fs::path& dir);
  template <typename T>
  void record(Ring<T>& ring, const T& item, bool wait_for_room);
  void on_trajectory_message(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void offer(std::unique_ptr<ActiveTrajectory> trajectory);
  void snapshot(bool final);
  void publish_status(lcm::LCM& lcm, const StatusSnapshot& s);
  void log_minute(const StatusSnapshot& s);
  void reloading();
  void request_reload();
  void take_reloads();
  void warn_rate_limited(const std::string& message);
  [[nodiscard]] bool inputs_done() const noexcept {
    return lidar_done_.load(std::memory_order_acquire) && gnss_done_.load(std::memory_order_acquire) &&
           imu_done_.load(std::memory_order_acquire);
  }

  // `notify`: wake the processing thread now; a paced replay wakes it once per batch.
  template <typename T, typename Fill>
  bool push(Ring<T>& ring, bool wait_for_room, Fill fill, bool notify = true) {
    T* slot = ring.try_claim();
    while (slot == nullptr) {
      if (!wait_for_room || stop_.load(std::memory_order_relaxed)) {
        ring.count_drop();
        return false;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(50));
      slot = ring.try_claim();
    }
    fill(*slot);
    slot->arrival_ns = steady_ns();
    slot->seq = g_sequence.fetch_add(1, std::memory_order_relaxed);
    ring.publish();
    if (notify) process_wake_.notify();
    return true;
  }
  void push_serial(Ring<SerialItem>& ring, bool wait, std::span<const std::uint8_t> bytes, std::int64_t receive_ns,
                   bool notify = true);

  DaemonConfig config_;
  RunOptions options_;
  pose::GlobalFrame frame_;

  // Sources, opened before READY.
  std::unique_ptr<vlp16::UdpSource> udp_;
  std::unique_ptr<serial::SerialPortSource> gnss_port_, imu_port_;
  std::unique_ptr<vlp16::PcapSource> pcap_;
  std::unique_ptr<serial::ReplaySource> gnss_replay_, imu_replay_;
  std::unique_ptr<SweepProcessor> processor_;
  std::int64_t last_lidar_receive_ns_ = 0;  // processing-owned

  Ring<LidarItem> lidar_;
  Ring<SerialItem> gnss_, imu_;
  Ring<Sweep> sweeps_;
  Ring<StatusSnapshot> status_;
  Ring<TrajectoryItem> trajectories_in_;   // publisher → processing
  Ring<TrajectoryItem> trajectories_out_;  // processing → publisher (to free)
  std::unique_ptr<Ring<LidarItem>> record_lidar_;
  std::unique_ptr<Ring<SerialItem>> record_gnss_, record_imu_;

  EventFd process_wake_, publish_wake_, record_wake_, main_wake_;
  std::atomic<bool> stop_{false};
  // SIGHUP reloads: requested by the main thread, read by reloading(), taken by the publisher.
  struct Reload {
    std::unique_ptr<ActiveTrajectory> trajectory;  // or why not
    std::string error;
  };
  std::mutex reload_mutex_;
  std::condition_variable reload_cv_;
  std::uint64_t reload_requests_ = 0;
  bool reload_stop_ = false;
  std::vector<Reload> reloads_;
  std::atomic<bool> lidar_done_{false}, gnss_done_{false}, imu_done_{false};
  std::atomic<bool> processing_done_{false}, publishing_done_{false};
  std::atomic<std::uint64_t> processing_beat_{0}, publishing_beat_{0};
  // CPU time of each kind of thread, added as each ends (for the summary).
  std::atomic<std::int64_t> cpu_sources_ns_{0}, cpu_processing_ns_{0}, cpu_publishing_ns_{0};
  std::atomic<std::uint64_t> oversize_datagrams_{0}, source_errors_{0}, serial_disconnects_{0};
  // Copied from the UDP source by its thread.
  std::atomic<std::uint64_t> rejected_sources_{0}, kernel_drops_{0};

  // Publisher-owned.
  std::array<std::uint64_t, kTrajectoryRejectCount> trajectory_rejects_{};
  std::uint64_t trajectories_accepted_ = 0, trajectory_reloads_ = 0, trajectory_reload_errors_ = 0;
  std::vector<double> latency_window_ms_, processing_window_ms_, latency_minute_ms_;
  LatencyHistogram latency_all_;  // the whole run, for the summary
  StatusSnapshot minute_start_;  // the status at the start of the current minute (log_minute)
  StatusSnapshot last_status_;
  std::int64_t start_steady_ns_ = 0;
  log::RateLimited warn_limit_;
};

void Daemon::warn_rate_limited(const std::string& message) {
  std::uint64_t suppressed = 0;
  if (warn_limit_.allow(steady_ns(), suppressed)) {
    if (suppressed > 0) {
      log::warn("{} ({} similar warnings suppressed)", message, suppressed);
    } else {
      log::warn("{}", message);
    }
  }
}

// The run folder's three recordings, from their start (again for each lap of --loop).
void Daemon::open_replay(bool first) {
  const fs::path& dir = *options_.replay;
  vlp16::PcapOptions pcap_options;
  pcap_options.ports = {vlp16::kDataPort, vlp16::kPositionPort};
  pcap_ = std::make_unique<vlp16::PcapSource>(dir / kLidarFile, pcap_options);
  const auto open_serial = [&](const char* name, std::atomic<bool>& done) -> std::unique_ptr<serial::ReplaySource> {
    if (!fs::exists(dir / name)) {
      if (first) log::warn("replay: {} absent: that stream is silent", (dir / name).string());
      done.store(true);
      return nullptr;
    }
    return std::make_unique<serial::ReplaySource>((dir / name).string());
  };
  gnss_replay_ = open_serial(kGnssFile, gnss_done_);
  imu_replay_ = open_serial(kImuFile, imu_done_);
}

void Daemon::open_sources() {
  if (options_.replay) {
    open_replay(true);
    return;
  }
  vlp16::UdpOptions udp;
  udp.bind_address = config_.lidar.bind_address;
  udp.data_port = config_.lidar.data_port;
  udp.position_port = config_.lidar.position_port;
  udp.receive_buffer_bytes = config_.lidar.receive_buffer_bytes;
  udp.sensor_address = config_.lidar.sensor_address;
  udp_ = std::make_unique<vlp16::UdpSource>(udp);
  if (const std::string w = udp_->receive_buffer_warning(); !w.empty()) log::warn("{}", w);
  log::info("lidar: UDP {}:{} (data), :{} (position), from {}", config_.lidar.bind_address, udp_->data_port(),
            udp_->position_port(), udp.sensor_address.empty() ? "any sender" : udp.sensor_address + " only");
  const auto open_port = [](const DaemonConfig::Serial& s, const char* what, std::atomic<bool>& done) {
    if (s.device.empty()) {
      log::warn("{}: no device configured: that stream is silent", what);
      done.store(true);
      return std::unique_ptr<serial::SerialPortSource>();
    }
    serial::SerialPortOptions o;
    o.device = s.device;
    o.baud = s.baud;
    // A receiver that comes back (cable, USB re-enumeration) is read again within 0.5 s.
    o.max_backoff = milliseconds(500);
    log::info("{}: {} at {} baud", what, s.device, s.baud);
    return std::make_unique<serial::SerialPortSource>(o);
  };
  gnss_port_ = open_port(config_.gnss, "gnss", gnss_done_);
  imu_port_ = open_port(config_.imu, "imu", imu_done_);
}

// ---- receive threads ------------------------------------------------------------------------

void Daemon::lidar_live() {
  if (const std::string w = apply_thread_config("trajroid-lidar", config_.realtime.lidar); !w.empty()) log::warn("{}", w);
  prefault_stack();
  vlp16::Datagram d;
  while (!stop_.load(std::memory_order_relaxed)) {
    const auto next = udp_->next(d, milliseconds(kIdleWait_ms));
    rejected_sources_.store(udp_->rejected_sources(), std::memory_order_relaxed);
    kernel_drops_.store(udp_->kernel_drops(), std::memory_order_relaxed);
    if (next == vlp16::PacketSource::Next::kTimeout) continue;
    if (next != vlp16::PacketSource::Next::kDatagram) {
      source_errors_.fetch_add(1, std::memory_order_relaxed);
      warn_rate_limited("lidar: " + udp_->error());
      continue;
    }
    if (d.payload.size() > kMaxDatagram) {
      oversize_datagrams_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    // Kernel stamps are CLOCK_REALTIME; the daemon's host clock is CLOCK_MONOTONIC.
    const std::int64_t receive_ns = d.receive_time_ns - (clock_ns(CLOCK_REALTIME) - clock_ns(CLOCK_MONOTONIC));
    const LidarPort port = d.destination_port == udp_->position_port() ? LidarPort::kPosition : LidarPort::kData;
    push(lidar_, false, [&](LidarItem& item) {
      item.receive_ns = receive_ns;
      item.port = port;
      item.size = static_cast<std::uint16_t>(d.payload.size());
      std::copy(d.payload.begin(), d.payload.end(), item.bytes.begin());
    });
  }
  cpu_sources_ns_.fetch_add(thread_cpu_ns());
  lidar_done_.store(true, std::memory_order_release);
}

void Daemon::push_serial(Ring<SerialItem>& ring, bool wait, std::span<const std::uint8_t> bytes, std::int64_t receive_ns,
                         bool notify) {
  for (std::size_t at = 0; at < bytes.size(); at += kMaxChunk) {
    const auto piece = bytes.subspan(at, std::min(kMaxChunk, bytes.size() - at));
    push(
        ring, wait,
        [&](SerialItem& item) {
          item.receive_ns = receive_ns;
          item.size = static_cast<std::uint16_t>(piece.size());
          std::copy(piece.begin(), piece.end(), item.bytes.begin());
        },
        notify);
  }
}

void Daemon::serial_live(serial::SerialPortSource& source, Ring<SerialItem>& ring, std::atomic<bool>& done,
                         const char* name, const ThreadConfig& thread) {
  if (const std::string w = apply_thread_config(name, thread); !w.empty()) log::warn("{}", w);
  prefault_stack();
  serial::Chunk chunk;
  std::uint64_t opens = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    const serial::ReadStatus status = source.read(chunk, milliseconds(kIdleWait_ms));
    if (source.counters().opens != opens) {
      opens = source.counters().opens;
      log::info("{}: {} open ({} backend)", name, source.describe(),
                source.backend() == serial::SerialPortSource::Backend::kTermios ? "termios" : "libserialport");
    }
    if (status == serial::ReadStatus::kData) {
      push_serial(ring, false, chunk.bytes, chunk.receive_time_ns);
    } else if (status == serial::ReadStatus::kDisconnected) {
      serial_disconnects_.fetch_add(1, std::memory_order_relaxed);
      // Rare and important: every one is logged (a reopen follows within the backoff, ≤ 0.5 s).
      log::warn("{}: {} disconnected ({}); reopening", name, source.describe(), source.last_error());
    }
  }
  cpu_sources_ns_.fetch_add(thread_cpu_ns());
  done.store(true, std::memory_order_release);
}

// One thread reads the three recordings and merges them by their recorded receive time, so
// the processing order, and with it the output, is the same on every run.
void Daemon::replay() {
  (void)apply_thread_config("trajroid-replay", config_.realtime.lidar);
  struct Pending {
    bool have = false;
    std::int64_t t = 0;
    LidarPort port = LidarPort::kData;
    std::vector<std::uint8_t> bytes;
  };
  Pending lidar, gnss, imu;
  vlp16::Datagram d;
  // --loop: added to every recorded time, one lap's span (plus a gap) more each lap.
  constexpr std::int64_t kLapGap_ns = 100'000'000;
  std::int64_t shift = 0, lap_first = INT64_MAX, lap_last = INT64_MIN;
  std::uint64_t lap = 1;
  const auto next_lidar = [&] {
    for (;;) {
      const auto r = pcap_->next(d);
      if (r != vlp16::PacketSource::Next::kDatagram) {
        if (r == vlp16::PacketSource::Next::kError) log::warn("replay: {}", pcap_->error());
        lidar.have = false;
        return;
      }
      if (d.payload.size() > kMaxDatagram) {
        oversize_datagrams_.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      lidar.have = true;
      lidar.t = d.receive_time_ns + shift;
      lidar.port = d.destination_port == vlp16::kPositionPort ? LidarPort::kPosition : LidarPort::kData;
      lidar.bytes.assign(d.payload.begin(), d.payload.end());
      return;
    }
  };
  const auto next_serial = [&shift](serial::ReplaySource* source, Pending& p) {
    serial::Chunk chunk;
    p.have = source != nullptr && source->read(chunk, milliseconds(0)) == serial::ReadStatus::kData;
    if (p.have) {
      p.t = chunk.receive_time_ns + shift;
      p.bytes.assign(chunk.bytes.begin(), chunk.bytes.end());
    }
  };
  next_lidar();
  next_serial(gnss_replay_.get(), gnss);
  next_serial(imu_replay_.get(), imu);

  // Paced: items due within one quantum of now go out together and wake the processing
  // thread once; between batches the thread sleeps to an absolute deadline. This keeps the
  // reader's own cost (a timer wake-up and an eventfd write per packet otherwise) small
  // beside the processing it feeds; items leave at most one quantum early.
  constexpr std::int64_t kPacingQuantum_ns = 2'000'000;
  constexpr int kMaxBatch = 16;  // a replay running behind still wakes the processing thread
  const bool paced = options_.rate > 0.0;
  bool anchored = false;
  int unnotified = 0;
  std::int64_t t0 = 0, wall0 = 0;
  for (;;) {
    if (!lidar.have && !gnss.have && !imu.have) {
      if (!options_.loop || stop_.load(std::memory_order_relaxed) || lap_first > lap_last) break;
      shift += lap_last - lap_first + kLapGap_ns;
      lap_first = INT64_MAX;
      lap_last = INT64_MIN;
      open_replay(false);
      next_lidar();
      next_serial(gnss_replay_.get(), gnss);
      next_serial(imu_replay_.get(), imu);
      log::info("replay: lap {}", ++lap);
      continue;
    }
    if (stop_.load(std::memory_order_relaxed)) break;
    Pending* p = nullptr;
    for (Pending* c : {&gnss, &imu, &lidar}) {
      if (c->have && (p == nullptr || c->t < p->t)) p = c;
    }
    if (p == nullptr) break;  // cannot happen (one of them has an item); for the compiler
    if (paced) {
      if (!anchored) {
        anchored = true;
        t0 = p->t;
        wall0 = steady_ns();
      }
      const auto due = wall0 + static_cast<std::int64_t>(static_cast<double>(p->t - t0) / options_.rate);
      if (unnotified >= kMaxBatch || (unnotified > 0 && due > steady_ns() + kPacingQuantum_ns)) {
        process_wake_.notify();
        unnotified = 0;
      }
      if (due > steady_ns() + kPacingQuantum_ns) sleep_until_steady(due, stop_);
    }
    lap_first = std::min(lap_first, p->t);
    lap_last = std::max(lap_last, p->t);
    // As fast as possible: wait for room (exact output); paced: drop when full, as live.
    const bool notify = !paced;
    if (p == &lidar) {
      push(
          lidar_, !paced,
          [&](LidarItem& item) {
            item.receive_ns = lidar.t;
            item.port = lidar.port;
            item.size = static_cast<std::uint16_t>(lidar.bytes.size());
            std::copy(lidar.bytes.begin(), lidar.bytes.end(), item.bytes.begin());
          },
          notify);
      next_lidar();
    } else if (p == &gnss) {
      push_serial(gnss_, !paced, gnss.bytes, gnss.t, notify);
      next_serial(gnss_replay_.get(), gnss);
    } else {
      push_serial(imu_, !paced, imu.bytes, imu.t, notify);
      next_serial(imu_replay_.get(), imu);
    }
    if (paced) ++unnotified;
  }
  cpu_sources_ns_.fetch_add(thread_cpu_ns());
  lidar_done_.store(true, std::memory_order_release);
  gnss_done_.store(true, std::memory_order_release);
  imu_done_.store(true, std::memory_order_release);
  process_wake_.notify();
}

// ---- processing -----------------------------------------------------------------------------

void Daemon::snapshot(bool final) {
  StatusSnapshot* s = status_.try_claim();
  if (s == nullptr) {
    status_.count_drop();
    return;
  }
  const SweepProcessor& p = *processor_;
  const vlp16::StreamCounters& l = p.lidar_counters();
  s->steady_ns = steady_ns();
  s->final = final;
  s->trajectory_id = p.active_trajectory_id();
  s->processor = p.counters();
  s->lidar_packets = l.data_packets;
  s->position_packets = l.position_packets;
  s->lost_packets = l.lost_packets;
  s->decode_errors = l.rejected_total();
  const Sweep& current = p.current();
  s->pose_valid = current.pose_status == pose::PoseStatus::kValid;
  s->pose_status = current.pose_status;
  const pose::GnssFix* fix = p.poses().newest_fix();
  s->pose_age_s = fix != nullptr ? static_cast<double>(last_lidar_receive_ns_ - fix->t_ns) * 1e-9 : -1.0;
  s->fix_type = fix != nullptr ? fix->quality.fix_type : 0;
  s->h_acc_m = fix != nullptr ? fix->quality.h_acc_m : 0.0;

  s->counter_count = 0;
  s->add("ring_drops.lidar", lidar_.dropped());
  s->add("ring_drops.gnss", gnss_.dropped());
  s->add("ring_drops.imu", imu_.dropped());
  s->add("ring_drops.sweeps", sweeps_.dropped());
  s->add("ring_drops.status", status_.dropped());
  s->add("ring_drops.trajectory", trajectories_in_.dropped());
  if (record_lidar_) {
    s->add("ring_drops.record_lidar", record_lidar_->dropped());
    s->add("ring_drops.record_gnss", record_gnss_->dropped());
    s->add("ring_drops.record_imu", record_imu_->dropped());
  }
  s->add("lidar.oversize_datagrams", oversize_datagrams_.load(std::memory_order_relaxed));
  s->add("lidar.source_errors", source_errors_.load(std::memory_order_relaxed));
  s->add("lidar.rejected_source", rejected_sources_.load(std::memory_order_relaxed));
  s->add("lidar.kernel_drops", kernel_drops_.load(std::memory_order_relaxed));
  for (std::size_t i = 1; i < vlp16::kPacketErrorCount; ++i) {
    s->add(vlp16::to_string(static_cast<vlp16::PacketError>(i)), l.rejected[i]);
  }
  s->add("lidar.out_of_order", l.out_of_order);
  s->add("lidar.restarts", l.restarts);
  s->add("lidar.late_dropped", l.late_dropped);
  s->add("lidar.duplicates", l.duplicates);
  s->add("lidar.clock_resets", l.clock_resets);
  s->add("lidar.no_return", l.no_return);
  s->add("lidar.out_of_range", l.out_of_range);
  s->add("lidar.partial_sweeps", l.partial_frames);
  s->add("lidar.position_wrong_size", l.position_wrong_size);
  for (std::size_t i = 1; i < vlp16::kNmeaErrorCount; ++i) {
    s->add(vlp16::to_string(static_cast<vlp16::NmeaError>(i)), l.nmea[i]);
  }
  const auto framing = [s](const char* bytes, const char* frames, const char* skipped, const char* checksum,
                           const char* lengths, const framing::FramerCounters& f) {
    s->add(bytes, f.bytes);
    s->add(frames, f.frames);
    s->add(skipped, f.skipped_bytes);
    s->add(checksum, f.checksum_errors);
    s->add(lengths, f.bad_lengths + f.unsizable);
  };
  const pose_input::PoseInput& in = p.pose_input();
  framing("gnss.bytes", "gnss.frames", "gnss.skipped_bytes", "gnss.checksum_errors", "gnss.bad_lengths",
          in.gnss_framing());
  framing("imu.bytes", "imu.frames", "imu.skipped_bytes", "imu.checksum_errors", "imu.bad_lengths", in.imu_framing());
  s->add("serial.disconnects", serial_disconnects_.load(std::memory_order_relaxed));
  const pose_input::PoseInputCounters& pc = in.counters();
  s->add("pose.fixes", pc.fixes);
  s->add("pose.high_precision_fixes", pc.high_precision);
  s->add("pose.invalid_position", pc.invalid_position);
  s->add("pose.malformed_messages", pc.malformed);
  s->add("pose.attitudes", pc.attitudes);
  s->add("pose.imu_without_attitude", pc.imu_without_attitude);
  s->add("pose.refused_samples", pc.refused);
  s->add("pose.gnss_clock_resets", in.gnss_clock().resets());
  s->add("pose.imu_clock_resets", in.imu_clock().resets());
  s->add("sweeps.points_truncated", p.counters().points_truncated);
  s->add("trajectory.swaps", p.counters().trajectory_swaps);
  s->add("trajectory.projection_reacquired", p.counters().projection_reacquired);
  status_.publish();
  publish_wake_.notify();
}

template <typename T>
void Daemon::record(Ring<T>& ring, const T& item, bool wait_for_room) {
  T* slot = ring.try_claim();
  while (slot == nullptr && wait_for_room && !stop_.load(std::memory_order_relaxed)) {
    record_wake_.notify();
    std::this_thread::sleep_for(std::chrono::microseconds(20));
    slot = ring.try_claim();
  }
  if (slot == nullptr) {
    ring.count_drop();
    return;
  }
  *slot = item;
  ring.publish();
}

void Daemon::processing() {
  if (const std::string w = apply_thread_config("trajroid-proc", config_.realtime.processing); !w.empty()) {
    log::warn("{}", w);
  }
  prefault_stack();
  // An as-fast-as-possible replay waits for room downstream: its output is exact.
  const bool exact = options_.replay.has_value() && options_.rate == 0.0;
  RingSink sink(sweeps_, publish_wake_, exact, stop_);
  std::int64_t next_status = steady_ns() + kSecond_ns;
  const std::int64_t stall_at = options_.stall_processing_after_s
                                    ? steady_ns() + static_cast<std::int64_t>(*options_.stall_processing_after_s * 1e9)
                                    : std::numeric_limits<std::int64_t>::max();
  for (;;) {
    if (steady_ns() >= stall_at) {
      log::warn("fault injection: the processing thread stops making progress");
      while (!stop_.load(std::memory_order_relaxed)) std::this_thread::sleep_for(milliseconds(50));
      break;
    }
    processing_beat_.fetch_add(1, std::memory_order_relaxed);
    while (TrajectoryItem* t = trajectories_in_.front()) {
      processor_->offer_trajectory(std::move(t->trajectory));
      trajectories_in_.release();
    }
    if (auto retired = processor_->take_retired()) {
      if (TrajectoryItem* slot = trajectories_out_.try_claim()) {
        slot->trajectory = std::move(retired);
        trajectories_out_.publish();
      }  // else: freed here, once (rare: the publisher has not collected 8 of them)
    }

    // The items waiting, oldest sequence first, at most a batch before the checks above.
    int handled = 0;
    for (; handled < 256; ++handled) {
      LidarItem* l = lidar_.front();
      SerialItem* g = gnss_.front();
      SerialItem* m = imu_.front();
      const std::uint64_t none = ~std::uint64_t{0};
      const std::uint64_t ls = l ? l->seq : none, gs = g ? g->seq : none, ms = m ? m->seq : none;
      if (ls == none && gs == none && ms == none) break;
      if (ls < gs && ls < ms) {
        const std::int64_t start = steady_ns();
        sink.packet_started(start);
        processor_->set_input_arrival(l->arrival_ns);
        last_lidar_receive_ns_ = l->receive_ns;
        processor_->lidar_datagram(l->port, std::span<const std::uint8_t>(l->bytes.data(), l->size), l->receive_ns, sink);
        sink.packet_done(steady_ns());
        if (record_lidar_) record(*record_lidar_, *l, exact);
        lidar_.release();
      } else {
        const bool is_gnss = gs < ms;
        SerialItem* s = is_gnss ? g : m;
        const std::span<const std::uint8_t> bytes(s->bytes.data(), s->size);
        if (is_gnss) {
          processor_->gnss_bytes(bytes, s->receive_ns);
        } else {
          processor_->imu_bytes(bytes, s->receive_ns);
        }
        if (Ring<SerialItem>* ring = is_gnss ? record_gnss_.get() : record_imu_.get()) record(*ring, *s, exact);
        (is_gnss ? gnss_ : imu_).release();
      }
    }
    if (handled > 0 && record_lidar_) record_wake_.notify();

    const std::int64_t now = steady_ns();
    if (now >= next_status) {
      snapshot(false);
      next_status += kSecond_ns;
      if (next_status < now) next_status = now + kSecond_ns;
    }
    // Stopping (SIGTERM) or at the end of a replay: what was received is processed, and the
    // sweep in progress goes out (partial) — nothing already received is lost.
    const bool stopping = stop_.load(std::memory_order_relaxed);
    if (handled == 0 && (stopping || (inputs_done() && lidar_.size() == 0 && gnss_.size() == 0 && imu_.size() == 0))) {
      processor_->flush(sink);
      break;
    }
    if (handled == 0) process_wake_.wait(kIdleWait_ms);
  }
  snapshot(true);
  cpu_processing_ns_.fetch_add(thread_cpu_ns());
  processing_done_.store(true, std::memory_order_release);
  publish_wake_.notify();
  record_wake_.notify();
}

// ---- publishing -----------------------------------------------------------------------------

void Daemon::offer(std::unique_ptr<ActiveTrajectory> trajectory) {
  TrajectoryItem* slot = trajectories_in_.try_claim();
  if (slot == nullptr) {
    trajectories_in_.count_drop();
    return;
  }
  slot->trajectory = std::move(trajectory);
  trajectories_in_.publish();
  process_wake_.notify();
}

void Daemon::on_trajectory_message(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
  TrajectoryCheck check = decode_trajectory(buffer->data, buffer->data_size, frame_);
  if (check.reason != TrajectoryReject::kNone) {
    ++trajectory_rejects_[static_cast<std::size_t>(check.reason)];
    warn_rate_limited("trajectory on " + channel + " rejected: " + std::string(to_string(check.reason)) + " (" +
                      check.detail + "); the active one stays");
    return;
  }
  ++trajectories_accepted_;
  log::info("trajectory {} accepted: {} waypoints, {:.1f} m; active from the next sweep", check.trajectory->id,
            check.trajectory->trajectory.waypoints().size(), check.trajectory->trajectory.length_m());
  offer(std::move(check.trajectory));
}

void Daemon::publish_status(lcm::LCM& lcm, const StatusSnapshot& s) {
  trajroi::status_t m;
  m.wall_time_ns = clock_ns(CLOCK_REALTIME);
  m.uptime_s = static_cast<double>(s.steady_ns - start_steady_ns_) * 1e-9;
  m.replay = options_.replay.has_value();
  m.final_status = s.final;
  m.trajectory_id = s.trajectory_id;
  m.lidar_packets = static_cast<std::int64_t>(s.lidar_packets);
  m.position_packets = static_cast<std::int64_t>(s.position_packets);
  m.lost_packets = static_cast<std::int64_t>(s.lost_packets);
  m.decode_errors = static_cast<std::int64_t>(s.decode_errors);
  m.sweeps = static_cast<std::int64_t>(s.processor.sweeps);
  m.sweeps_published = static_cast<std::int64_t>(s.processor.sweeps_filtered);
  m.sweeps_without_pose = static_cast<std::int64_t>(s.processor.sweeps_without_pose);
  m.points_in = static_cast<std::int64_t>(s.processor.points_in);
  m.points_kept = static_cast<std::int64_t>(s.processor.points_kept);
  m.ring_drops = static_cast<std::int64_t>(s.ring_drops());
  m.pose_valid = s.pose_valid;
  m.pose_status = std::string(pose::to_string(s.pose_status));
  m.pose_age_s = s.pose_age_s;
  m.fix_type = static_cast<std::int8_t>(s.fix_type);
  m.h_acc_m = s.h_acc_m;
  m.processing_ms_p50 = percentile(processing_window_ms_, 0.50);
  m.processing_ms_p99 = percentile(processing_window_ms_, 0.99);
  m.latency_ms_p50 = percentile(latency_window_ms_, 0.50);
  m.latency_ms_p99 = percentile(latency_window_ms_, 0.99);
  for (std::size_t i = 0; i < s.counter_count; ++i) {
    m.counter_names.emplace_back(s.counters[i].name);
    m.counter_values.push_back(static_cast<std::int64_t>(s.counters[i].value));
  }
  for (std::size_t i = 1; i < kTrajectoryRejectCount; ++i) {
    m.counter_names.push_back("trajectory.rejected: " + std::string(to_string(static_cast<TrajectoryReject>(i))));
    m.counter_values.push_back(static_cast<std::int64_t>(trajectory_rejects_[i]));
  }
  m.counter_names.emplace_back("trajectory.accepted");
  m.counter_values.push_back(static_cast<std::int64_t>(trajectories_accepted_));
  m.counter_names.emplace_back("trajectory.reloads");
  m.counter_values.push_back(static_cast<std::int64_t>(trajectory_reloads_));
  m.counter_names.emplace_back("trajectory.reload_errors");
  m.counter_values.push_back(static_cast<std::int64_t>(trajectory_reload_errors_));
  m.num_counters = static_cast<std::int32_t>(m.counter_names.size());
  lcm.publish(config_.lcm.status, &m);

  const double kept_pct = m.points_in > 0 ? 100.0 * static_cast<double>(m.points_kept) / static_cast<double>(m.points_in) : 0.0;
  log::info("status: sweeps {} published {} withheld {} | points in {} kept {} ({:.1f} %) | latency p50 {:.2f} p99 {:.2f} ms | "
            "drops {} | lost packets {} | pose {} (fix {}, age {:.2f} s) | trajectory {}",
            m.sweeps, m.sweeps_published, m.sweeps_without_pose, m.points_in, m.points_kept, kept_pct, m.latency_ms_p50,
            m.latency_ms_p99, m.ring_drops, m.lost_packets, m.pose_status, static_cast<int>(m.fix_type), m.pose_age_s,
            m.trajectory_id);
  latency_window_ms_.clear();
  processing_window_ms_.clear();
  last_status_ = s;
  if (minute_start_.steady_ns == 0) minute_start_ = s;
  if (s.steady_ns - minute_start_.steady_ns >= 60'000'000'000 || s.final) log_minute(s);
}

// Once a minute, for the journal and soak tests: what the last minute did, and the memory.
void Daemon::log_minute(const StatusSnapshot& s) {
  const auto counter_value = [](const StatusSnapshot& snapshot, std::string_view name) -> std::uint64_t {
    for (std::size_t i = 0; i < snapshot.counter_count; ++i) {
      if (snapshot.counters[i].name == name) return snapshot.counters[i].value;
    }
    return 0;
  };
  long pages = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    long size = 0;
    if (std::fscanf(f, "%ld %ld", &size, &pages) != 2) pages = 0;
    std::fclose(f);
  }
  const double rss_mib = static_cast<double>(pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
  log::info("minute: {:.0f} s | sweeps {} published {} | latency p50 {:.2f} p99 {:.2f} max {:.2f} ms | ring drops {} | "
            "kernel drops {} | lost packets {} | RSS {:.1f} MiB",
            static_cast<double>(s.steady_ns - minute_start_.steady_ns) * 1e-9,
            s.processor.sweeps - minute_start_.processor.sweeps,
            s.processor.sweeps_filtered - minute_start_.processor.sweeps_filtered, percentile(latency_minute_ms_, 0.50),
            percentile(latency_minute_ms_, 0.99), percentile(latency_minute_ms_, 1.0),
            s.ring_drops() - minute_start_.ring_drops(),
            counter_value(s, "lidar.kernel_drops") - counter_value(minute_start_, "lidar.kernel_drops"),
            s.lost_packets - minute_start_.lost_packets, rss_mib);
  latency_minute_ms_.clear();
  minute_start_ = s;
}

void Daemon::publishing(lcm::LCM& lcm) {
  if (const std::string w = apply_thread_config("trajroid-pub", config_.realtime.publisher); !w.empty()) log::warn("{}", w);
  transport::subscribe_raw<&Daemon::on_trajectory_message>(lcm, config_.lcm.trajectory, this);
  latency_window_ms_.reserve(4096);
  processing_window_ms_.reserve(4096);
  latency_minute_ms_.reserve(1U << 16);
  trajroi::points_t points;
  trajroi::pose_t pose;
  trajroi::roi_t roi;
  points.x.reserve(config_.buffers.max_points_per_sweep);  // and the others grow once
  bool final_seen = false;
  for (;;) {
    publishing_beat_.fetch_add(1, std::memory_order_relaxed);
    pollfd fds[2] = {{lcm.getFileno(), POLLIN, 0}, {publish_wake_.fd(), POLLIN, 0}};
    if (poll(fds, 2, kIdleWait_ms) > 0) {
      if ((fds[0].revents & POLLIN) != 0) lcm.handleTimeout(0);
      if ((fds[1].revents & POLLIN) != 0) publish_wake_.drain();
    }
    while (Sweep* s = sweeps_.front()) {
      fill_pose(*s, pose);
      lcm.publish(config_.lcm.pose, &pose);
      if (s->filtered) {
        fill_roi(*s, roi);
        lcm.publish(config_.lcm.roi, &roi);
        fill_points(*s, config_.pose_mode, points);
        lcm.publish(config_.lcm.points, &points);
        const double latency_ms = static_cast<double>(steady_ns() - s->last_packet_arrival_ns) * 1e-6;
        if (latency_window_ms_.size() < latency_window_ms_.capacity()) latency_window_ms_.push_back(latency_ms);
        if (latency_minute_ms_.size() < latency_minute_ms_.capacity()) latency_minute_ms_.push_back(latency_ms);
        latency_all_.add(latency_ms);
      } else {
        warn_rate_limited("sweep " + std::to_string(s->index) + " withheld: no valid pose (" +
                          std::string(pose::to_string(s->pose_status)) + ")");
      }
      if (processing_window_ms_.size() < processing_window_ms_.capacity()) {
        processing_window_ms_.push_back(static_cast<double>(s->processing_ns) * 1e-6);
      }
      sweeps_.release();
    }
    while (StatusSnapshot* s = status_.front()) {
      publish_status(lcm, *s);
      final_seen = final_seen || s->final;
      status_.release();
    }
    while (TrajectoryItem* t = trajectories_out_.front()) {
      t->trajectory.reset();
      trajectories_out_.release();
    }
    take_reloads();
    if (processing_done_.load(std::memory_order_acquire) && sweeps_.size() == 0 && status_.size() == 0 &&
        (final_seen || stop_.load(std::memory_order_relaxed))) {
      break;
    }
  }
  cpu_publishing_ns_.fetch_add(thread_cpu_ns());
  publishing_done_.store(true, std::memory_order_release);
  main_wake_.notify();
}

// SIGHUP re-reads the trajectory file on this thread, off the publishing thread: reading and
// checking a large file (up to a million waypoints) must not hold up publication. Requests
// that come while a file is being read are served by one more read afterwards.
void Daemon::reloading() {
  pthread_setname_np(pthread_self(), "trajroid-reload");
  std::unique_lock<std::mutex> lock(reload_mutex_);
  for (;;) {
    reload_cv_.wait(lock, [this] { return reload_requests_ > 0 || reload_stop_; });
    if (reload_stop_) return;
    reload_requests_ = 0;
    lock.unlock();
    Reload r;
    try {
      r.trajectory = load_trajectory(config_.trajectory_file);
    } catch (const std::exception& e) {
      r.error = e.what();
    }
    lock.lock();
    reloads_.push_back(std::move(r));
    publish_wake_.notify();
  }
}

void Daemon::request_reload() {
  {
    std::lock_guard<std::mutex> lock(reload_mutex_);
    ++reload_requests_;
  }
  reload_cv_.notify_one();
}

// Publisher: offers what the reload thread loaded (the mutex is held for a vector swap only).
void Daemon::take_reloads() {
  std::vector<Reload> done;
  {
    std::lock_guard<std::mutex> lock(reload_mutex_);
    if (reloads_.empty()) return;
    done.swap(reloads_);
  }
  for (Reload& r : done) {
    if (r.trajectory) {
      offer(std::move(r.trajectory));
      ++trajectory_reloads_;
      log::info("SIGHUP: trajectory reloaded from {}; active from the next sweep", config_.trajectory_file.string());
    } else {
      ++trajectory_reload_errors_;
      log::error("SIGHUP: trajectory not reloaded, the active one stays: {}", r.error);
    }
  }
}

// ---- recording ------------------------------------------------------------------------------

void Daemon::recording() {
  pthread_setname_np(pthread_self(), "trajroid-rec");
  try {
    record_to(*options_.record);
  } catch (const std::exception& e) {
    // The pipeline goes on; what cannot be recorded piles up in the record rings, counted.
    log::error("--record stopped: {}", e.what());
  }
}

void Daemon::record_to(const fs::path& dir) {
  vlp16::PcapWriter pcap(dir / kLidarFile);
  serial::RecordingWriter gnss((dir / kGnssFile).string());
  serial::RecordingWriter imu((dir / kImuFile).string());
  for (;;) {
    bool any = false;
    while (LidarItem* l = record_lidar_->front()) {
      pcap.write(l->receive_ns, l->port == LidarPort::kData ? vlp16::kDataPort : vlp16::kPositionPort,
                 std::span<const std::uint8_t>(l->bytes.data(), l->size));
      record_lidar_->release();
      any = true;
    }
    for (auto [ring, writer] : {std::pair{record_gnss_.get(), &gnss}, std::pair{record_imu_.get(), &imu}}) {
      while (SerialItem* s = ring->front()) {
        writer->write(serial::Chunk{std::span<const std::uint8_t>(s->bytes.data(), s->size), s->receive_ns});
        ring->release();
        any = true;
      }
    }
    if (!any && processing_done_.load(std::memory_order_acquire)) break;
    if (!any) record_wake_.wait(kIdleWait_ms);
  }
  pcap.close();
  gnss.flush();
  imu.flush();
}

// ---- main -----------------------------------------------------------------------------------

int Daemon::run() {
  start_steady_ns_ = steady_ns();
  try {
    auto trajectory = load_trajectory(config_.trajectory_file);
    log::info("trajectory: {} ({} waypoints, {:.1f} m)", config_.trajectory_file.string(),
              trajectory->trajectory.waypoints().size(), trajectory->trajectory.length_m());
    processor_ = std::make_unique<SweepProcessor>(config_, std::move(trajectory));
  } catch (const std::exception& e) {
    // The trajectory file or the lidar calibration: both part of the configuration.
    log::critical("{}: {}", config_.file.string(), e.what());
    return kExitConfig;
  }
  try {
    open_sources();
  } catch (const std::exception& e) {
    log::critical("cannot open the sources: {}", e.what());
    return 1;
  }
  const std::string url = options_.lcm_url.empty() ? config_.lcm.url : options_.lcm_url;
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    log::critical("LCM: cannot open '{}' (is there a route for multicast? try ?ttl=0 on loopback)", url);
    return 1;
  }
  if (options_.record) {
    std::error_code ec;
    fs::create_directories(*options_.record, ec);
    if (ec) {
      log::critical("--record {}: {}", options_.record->string(), ec.message());
      return 1;
    }
    record_lidar_ = std::make_unique<Ring<LidarItem>>(config_.buffers.lidar_packets);
    record_gnss_ = std::make_unique<Ring<SerialItem>>(config_.buffers.serial_chunks);
    record_imu_ = std::make_unique<Ring<SerialItem>>(config_.buffers.serial_chunks);
  }
  if (config_.realtime.lock_memory) {
    if (const std::string w = lock_memory(); !w.empty()) log::warn("{}", w);
  }

  // Signals go to the main thread only, through a signalfd.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  const int sfd = signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC);

  std::vector<std::thread> threads;
  std::thread reload_thread([this] { reloading(); });
  threads.emplace_back([this] { processing(); });
  threads.emplace_back([this, &lcm] { publishing(lcm); });
  if (options_.record) threads.emplace_back([this] { recording(); });
  if (options_.replay) {
    threads.emplace_back([this] { replay(); });
  } else {
    threads.emplace_back([this] { lidar_live(); });
    if (gnss_port_) {
      threads.emplace_back([this] { serial_live(*gnss_port_, gnss_, gnss_done_, "trajroid-gnss", config_.realtime.gnss); });
    }
    if (imu_port_) {
      threads.emplace_back([this] { serial_live(*imu_port_, imu_, imu_done_, "trajroid-imu", config_.realtime.imu); });
    }
  }
  sd_notify(0, "READY=1\nSTATUS=running");
  log::info("trajroid running: {} → LCM {} ({}, {}, {}, {}; trajectory input on {})",
            options_.replay ? "replay of " + options_.replay->string() : std::string("live sensors"), url,
            config_.lcm.points, config_.lcm.pose, config_.lcm.roi, config_.lcm.status, config_.lcm.trajectory);

  std::uint64_t watchdog_usec = 0;
  const bool watchdog = sd_watchdog_enabled(0, &watchdog_usec) > 0;
  const int wait_ms = watchdog ? static_cast<int>(std::max<std::uint64_t>(watchdog_usec / 4000, 10)) : 1000;
  std::uint64_t last_processing = 0, last_publishing = 0;
  for (;;) {
    pollfd fds[2] = {{sfd, POLLIN, 0}, {main_wake_.fd(), POLLIN, 0}};
    (void)poll(fds, 2, wait_ms);
    if ((fds[0].revents & POLLIN) != 0) {
      signalfd_siginfo info{};
      while (read(sfd, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
        if (info.ssi_signo == SIGHUP) {
          log::info("SIGHUP: reloading the trajectory");
          request_reload();
        } else {
          log::info("{}: stopping", info.ssi_signo == SIGTERM ? "SIGTERM" : "SIGINT");
          sd_notify(0, "STOPPING=1");
          stop_.store(true);
        }
      }
    }
    if (publishing_done_.load(std::memory_order_acquire)) break;
    if (watchdog) {
      // Fed only while both the processing and the publishing loops turn.
      const std::uint64_t a = processing_beat_.load(std::memory_order_relaxed);
      const std::uint64_t b = publishing_beat_.load(std::memory_order_relaxed);
      if (a != last_processing && b != last_publishing) sd_notify(0, "WATCHDOG=1");
      last_processing = a;
      last_publishing = b;
    }
  }
  stop_.store(true);
  for (std::thread& t : threads) t.join();
  {
    std::lock_guard<std::mutex> lock(reload_mutex_);
    reload_stop_ = true;
  }
  reload_cv_.notify_one();
  reload_thread.join();
  close(sfd);

  const StatusSnapshot& s = last_status_;
  const std::uint64_t drops = s.ring_drops();
  const double wall_s = static_cast<double>(steady_ns() - start_steady_ns_) * 1e-9;
  log::info("summary: {:.2f} s | sweeps {} published {} withheld (no pose) {} | points in {} kept {} ({:.1f} %) | "
            "latency p50 {:.3f} ms p99 {:.3f} ms over {} sweeps | ring drops {} | lost packets {} | decode errors {}",
            wall_s, s.processor.sweeps, s.processor.sweeps_filtered, s.processor.sweeps_without_pose, s.processor.points_in,
            s.processor.points_kept,
            s.processor.points_in > 0 ? 100.0 * static_cast<double>(s.processor.points_kept) / static_cast<double>(s.processor.points_in) : 0.0,
            latency_all_.quantile(0.5), latency_all_.quantile(0.99), latency_all_.count(), drops,
            s.lost_packets, s.decode_errors);
  log::info("cpu: sources {:.3f} s ({}), processing {:.3f} s, publishing {:.3f} s",
            static_cast<double>(cpu_sources_ns_.load()) * 1e-9, options_.replay ? "replay reader" : "receive threads",
            static_cast<double>(cpu_processing_ns_.load()) * 1e-9, static_cast<double>(cpu_publishing_ns_.load()) * 1e-9);
  return 0;
}

}  // namespace

int run_daemon(const DaemonConfig& config, const RunOptions& options) {
  Daemon daemon(config, options);
  return daemon.run();
}

}  // namespace trajroi::daemon
