#include "publisher.hpp"

#include <poll.h>
#include <spdlog/fmt/fmt.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "realtime.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/input_source.hpp"
#include "trajroi/status_t.hpp"

namespace trajroi::daemon {

namespace {

double percentile(std::vector<double>& samples, double q) {
  if (samples.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(
      std::min(q * static_cast<double>(samples.size()), static_cast<double>(samples.size() - 1)));
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(k), samples.end());
  return samples[k];
}

double rss_mib() {
  long pages = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    long size = 0;
    if (std::fscanf(f, "%ld %ld", &size, &pages) != 2) pages = 0;
    std::fclose(f);
  }
  return static_cast<double>(pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

}  // namespace

Publisher::Publisher(Pipeline& pipeline, Outlet& outlet, Reloader* reloader, bool replay)
    : pipeline_(pipeline),
      outlet_(outlet),
      reloader_(reloader),
      replay_(replay),
      config_(pipeline.config),
      frame_(pose::GlobalFrame::local_cartesian(pipeline.config.origin)),
      start_steady_ns_(host::monotonic_ns()),
      health_(pipeline.config, !replay, start_steady_ns_),
      sweep_warn_limit_(pipeline.config.logging.warning_interval_s),
      trajectory_warn_limit_(pipeline.config.logging.warning_interval_s),
      late_limit_(pipeline.config.logging.warning_interval_s) {
  // Here, before the loops start: subscribing opens the receive socket (through liblcm, its
  // self test can take seconds), which must not hold up the publishing loop. For udpm://, the
  // outlet's start-up probe has already said whether this process's multicast comes back.
  const bool receiving = outlet_.subscribe(config_.lcm.trajectory,
                                           [this](std::span<const std::uint8_t> bytes, const std::string& channel) {
                                             on_trajectory_message(bytes, channel);
                                           });
  if (!receiving) {
    log::error(
        "LCM: this process does not receive its own multicast (its probe did not come back): trajectory messages on {} "
        "will not arrive. Under systemd the unit's IPAddressAllow= must admit this host's addresses "
        "(trajroid --unit-drop-in); otherwise check the multicast route and the firewall",
        config_.lcm.trajectory);
  }
}

void Publisher::warn_rate_limited(log::RateLimited& limit, const std::string& message) {
  std::uint64_t suppressed = 0;
  if (limit.allow(host::monotonic_ns(), suppressed)) {
    if (suppressed > 0) {
      log::warn("{} ({} similar warnings suppressed)", message, suppressed);
    } else {
      log::warn("{}", message);
    }
  }
}

template <typename Message>
void Publisher::send(const std::string& channel, const Message& m) {
  const int size = m.getEncodedSize();
  if (encoded_.size() < static_cast<std::size_t>(size)) encoded_.resize(static_cast<std::size_t>(size));
  (void)m.encode(encoded_.data(), 0, size);
  outlet_.publish(channel, std::span<const std::uint8_t>(encoded_.data(), static_cast<std::size_t>(size)));
}

void Publisher::offer(std::unique_ptr<pipeline::ActiveTrajectory> trajectory) {
  const bool pushed = pipeline_.trajectories_in.try_push(
      [&trajectory](TrajectoryItem& slot) { slot.trajectory = std::move(trajectory); });
  if (pushed) pipeline_.process_wake.notify();
}

void Publisher::on_trajectory_message(std::span<const std::uint8_t> bytes, const std::string& channel) {
  TrajectoryCheck check = decode_trajectory(bytes.data(), bytes.size(), frame_);
  if (check.reason != TrajectoryReject::kNone) {
    ++trajectory_rejects_[static_cast<std::size_t>(check.reason)];
    warn_rate_limited(trajectory_warn_limit_, "trajectory on " + channel +
                                                  " rejected: " + std::string(to_string(check.reason)) + " (" +
                                                  check.detail + "); the active one stays");
    return;
  }
  ++trajectories_accepted_;
  log::info("trajectory {} accepted: {} waypoints, {:.1f} m; active from the next sweep", check.trajectory->id,
            check.trajectory->trajectory.waypoints().size(), check.trajectory->trajectory.length_m());
  offer(std::move(check.trajectory));
}

void Publisher::take_reloads() {
  if (reloader_ == nullptr) return;
  for (Reloader::Result& r : reloader_->take()) {
    if (r.trajectory) {
      offer(std::move(r.trajectory));
      ++trajectory_reloads_;
      log::info("SIGHUP: trajectory reloaded from {}; active from the next sweep", reloader_->file().string());
    } else {
      ++trajectory_reload_errors_;
      log::error("SIGHUP: trajectory not reloaded, the active one stays: {}", r.error);
    }
  }
}

std::string Publisher::SweepTiming::describe() const {
  return fmt::format(
      "{:.2f} ms from its last packet to LCM (waiting for the processing thread {:.2f}, the closing packet and "
      "hand-over {:.2f}, waiting for the publisher {:.2f}, encoding {:.2f}, sending {:.2f} ms)",
      total_ms, processing_wait_ms, closing_ms, publisher_wait_ms, encoding_ms, sending_ms);
}

void Publisher::report_late(const SweepTiming& t, std::int64_t sent_ns) {
  ++late_sweeps_;
  std::uint64_t suppressed = 0;
  if (!late_limit_.allow(sent_ns, suppressed)) return;
  log::info("sweep {} late: {}; {} late sweeps (over {:.0f} ms) so far{}", t.index, t.describe(), late_sweeps_,
            kLateSweep_ms,
            suppressed > 0 ? " (" + std::to_string(suppressed) + " late sweeps not described)" : std::string());
}

void Publisher::publish_sweep(const pipeline::Sweep& s) {
  const std::int64_t dequeued_ns = host::monotonic_ns();
  fill_pose(s, pose_);
  send(config_.lcm.pose, pose_);
  if (s.filtered) {
    fill_roi(s, roi_);
    send(config_.lcm.roi, roi_);
    encode_points(s, config_.pose_mode, points_, points_encoded_);
    const std::int64_t encoded_ns = host::monotonic_ns();
    outlet_.publish(config_.lcm.points, points_encoded_);
    // A partial sweep's latency (the stream's end, flushed at a stop) is the wait for the stop,
    // not the pipeline's: left out of the figures.
    if (!s.partial) {
      const std::int64_t sent_ns = host::monotonic_ns();
      const auto ms = [](std::int64_t from, std::int64_t to) { return static_cast<double>(to - from) * 1e-6; };
      const SweepTiming timing{.index = s.index,
                               .total_ms = ms(s.last_packet_arrival_ns, sent_ns),
                               .processing_wait_ms = ms(s.last_packet_arrival_ns, s.closing_packet_start_ns),
                               .closing_ms = ms(s.closing_packet_start_ns, s.handed_over_ns),
                               .publisher_wait_ms = ms(s.handed_over_ns, dequeued_ns),
                               .encoding_ms = ms(dequeued_ns, encoded_ns),
                               .sending_ms = ms(encoded_ns, sent_ns)};
      const double latency_ms = timing.total_ms;
      if (latency_ms > slowest_in_minute_.total_ms) slowest_in_minute_ = timing;
      if (latency_ms > kLateSweep_ms && !pipeline_.exact) report_late(timing, sent_ns);
      if (latency_window_ms_.size() < latency_window_ms_.capacity()) latency_window_ms_.push_back(latency_ms);
      if (latency_minute_ms_.size() < latency_minute_ms_.capacity()) latency_minute_ms_.push_back(latency_ms);
      latency_all_.add(latency_ms);
    }
  } else {
    warn_rate_limited(sweep_warn_limit_, "sweep " + std::to_string(s.index) + " withheld: no valid pose (" +
                                             pose::describe(s.pose_status, s.pose_measured, s.pose_limit) + ")");
  }
  if (processing_window_ms_.size() < processing_window_ms_.capacity()) {
    processing_window_ms_.push_back(static_cast<double>(s.processing_ns) * 1e-6);
  }
}

void Publisher::publish_status(const StatusSnapshot& s) {
  trajroi::status_t m;
  m.wall_time_ns = host::realtime_ns();
  m.uptime_s = static_cast<double>(s.steady_ns - start_steady_ns_) * 1e-9;
  m.replay = replay_;
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
  m.host_minus_gnss_utc_s = s.host_minus_gnss_utc_s;
  m.lidar_pps_status = s.lidar_pps_status;
  m.lidar_gprmc_valid = s.lidar_gprmc_valid;
  m.processing_ms_p50 = percentile(processing_window_ms_, 0.50);
  m.processing_ms_p99 = percentile(processing_window_ms_, 0.99);
  m.latency_ms_p50 = percentile(latency_window_ms_, 0.50);
  m.latency_ms_p99 = percentile(latency_window_ms_, 0.99);
  const auto add = [&m](std::string name, std::uint64_t value) {
    m.counter_names.push_back(std::move(name));
    m.counter_values.push_back(static_cast<std::int64_t>(value));
  };
  for (std::size_t i = 0; i < kCounterCount; ++i)
    add(std::string(counter_name(i)), s.counters[i]);
  for (std::size_t i = 1; i < kTrajectoryRejectCount; ++i) {
    add("trajectory.rejected: " + std::string(to_string(static_cast<TrajectoryReject>(i))), trajectory_rejects_[i]);
  }
  add("trajectory.accepted", trajectories_accepted_);
  add("trajectory.reloads", trajectory_reloads_);
  add("trajectory.reload_errors", trajectory_reload_errors_);
  add("sweeps.late", late_sweeps_);
  m.num_counters = static_cast<std::int32_t>(m.counter_names.size());
  send(config_.lcm.status, m);

  const double kept_pct =
      m.points_in > 0 ? 100.0 * static_cast<double>(m.points_kept) / static_cast<double>(m.points_in) : 0.0;
  log::info(
      "status: sweeps {} published {} withheld {} | points in {} kept {} ({:.1f} %) | latency p50 {:.2f} p99 "
      "{:.2f} ms | drops {} | lost packets {} | pose {} (fix {}, age {:.2f} s) | trajectory {}",
      m.sweeps, m.sweeps_published, m.sweeps_without_pose, m.points_in, m.points_kept, kept_pct, m.latency_ms_p50,
      m.latency_ms_p99, m.ring_drops, m.lost_packets, m.pose_status, static_cast<int>(m.fix_type), m.pose_age_s,
      m.trajectory_id);
  // Faults said when they start and end; systemd told the state in words.
  for (const HealthLine& line : health_.update(s)) {
    if (line.level == HealthLine::Level::kWarning) {
      log::warn("{}", line.text);
    } else {
      log::info("{}", line.text);
    }
  }
  if (!s.final) sd_notify(0, ("STATUS=" + health_.state()).c_str());
  latency_window_ms_.clear();
  processing_window_ms_.clear();
  last_status_ = s;
  if (minute_start_.steady_ns == 0) minute_start_ = s;
  if (s.steady_ns - minute_start_.steady_ns >= 60'000'000'000 || s.final) log_minute(s);
}

// Once a minute, for the journal and soak tests: what the last minute did, and the memory.
void Publisher::log_minute(const StatusSnapshot& s) {
  // A late maximum says where its time went (an as-fast replay's queue is not lateness).
  const std::string slowest =
      slowest_in_minute_.total_ms > kLateSweep_ms && !pipeline_.exact
          ? fmt::format(" | slowest: sweep {} {}", slowest_in_minute_.index, slowest_in_minute_.describe())
          : std::string();
  log::info(
      "minute: {:.0f} s | sweeps {} published {} | latency p50 {:.2f} p99 {:.2f} max {:.2f} ms | ring drops {} | "
      "kernel drops {} | lost packets {} | RSS {:.1f} MiB{}",
      static_cast<double>(s.steady_ns - minute_start_.steady_ns) * 1e-9,
      s.processor.sweeps - minute_start_.processor.sweeps,
      s.processor.sweeps_filtered - minute_start_.processor.sweeps_filtered, percentile(latency_minute_ms_, 0.50),
      percentile(latency_minute_ms_, 0.99), percentile(latency_minute_ms_, 1.0),
      s.ring_drops() - minute_start_.ring_drops(),
      s[Counter::kLidarKernelDrops] - minute_start_[Counter::kLidarKernelDrops],
      s.lost_packets - minute_start_.lost_packets, rss_mib(), slowest);
  latency_minute_ms_.clear();
  slowest_in_minute_ = {};
  minute_start_ = s;
}

void Publisher::publish_pending_sweeps() {
  while (pipeline::Sweep* s = pipeline_.sweeps.front()) {
    publish_sweep(*s);
    pipeline_.sweeps.release();
  }
}

void Publisher::run() {
  if (const std::string w = apply_thread_config("trajroid-pub", config_.realtime.publisher); !w.empty()) {
    log::warn("{}", w);
  }
  const std::int64_t cpu_start = host::thread_cpu_ns();
  latency_window_ms_.reserve(4096);
  processing_window_ms_.reserve(4096);
  latency_minute_ms_.reserve(1U << 16);
  if (!pipeline_.exact) {
    // The largest sweep's encoding, resident from the start (see Pipeline::exact; a page over
    // for the head, whose size is that of an empty sweep's).
    encode_points(pipeline::Sweep{}, config_.pose_mode, points_, points_encoded_);
    points_encoded_.resize(points_encoded_.size() + 4096 +
                           config_.buffers.max_points_per_sweep * kEncodedBytesPerPoint);
    points_encoded_.clear();
  }
  bool final_seen = false;
  for (;;) {
    pipeline_.publishing_beat.fetch_add(1, std::memory_order_relaxed);
    pollfd fds[2] = {{outlet_.incoming_fd(), POLLIN, 0}, {pipeline_.publish_wake.fd(), POLLIN, 0}};
    if (poll(fds, 2, kIdleWait_ms) > 0) {
      if ((fds[0].revents & POLLIN) != 0) outlet_.handle_incoming();
      if ((fds[1].revents & POLLIN) != 0) pipeline_.publish_wake.drain();
    }
    publish_pending_sweeps();
    while (StatusSnapshot* s = pipeline_.status->front()) {
      // The sweeps handed over before this snapshot go out first, so that a status (the final
      // one above all) counts every sweep it says was published: the processing thread may
      // have queued a sweep and then the snapshot since the loop above emptied the ring.
      publish_pending_sweeps();
      publish_status(*s);
      final_seen = final_seen || s->final;
      pipeline_.status->release();
    }
    while (TrajectoryItem* t = pipeline_.trajectories_out.front()) {
      t->trajectory.reset();
      pipeline_.trajectories_out.release();
    }
    take_reloads();
    if (pipeline_.processing_done.load(std::memory_order_acquire) && pipeline_.sweeps.size() == 0 &&
        pipeline_.status->size() == 0 && (final_seen || pipeline_.stop.load(std::memory_order_relaxed))) {
      break;
    }
  }
  pipeline_.cpu_publishing_ns.fetch_add(host::thread_cpu_ns() - cpu_start);
  pipeline_.publishing_done.store(true, std::memory_order_release);
  pipeline_.main_wake.notify();
}

}  // namespace trajroi::daemon
