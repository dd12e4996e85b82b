#include "publisher.hpp"

#include <poll.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "realtime.hpp"
#include "service_notify.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/pipeline/pose_words.hpp"
#include "trajroi/status_t.hpp"
#include "trajroi/vlp16/model.hpp"

namespace trajroi::daemon {
namespace {

void say(const std::vector<HealthLine>& lines) {
  for (const HealthLine& line : lines) {
    if (line.level == HealthLine::Level::kWarning) {
      log::warn("{}", line.text);
    } else {
      log::info("{}", line.text);
    }
  }
}

}  // namespace

Publisher::Publisher(Pipeline& pipeline, Outlet& outlet, Reloader* reloader, bool replay,
                     const pipeline::ActiveTrajectory& trajectory)
    : pipeline_(pipeline),
      outlet_(outlet),
      replay_(replay),
      config_(pipeline.config),
      start_steady_ns_(host::monotonic_ns()),
      sender_(outlet, pipeline.config),
      trajectories_(pipeline, reloader, trajectory),
      latency_(pipeline.config.logging.warning_interval_s, !pipeline.exact),
      health_(pipeline.config, !replay, start_steady_ns_),
      corrections_(pipeline.config, pipeline.corrections.get(), !replay),
      sweep_warnings_(pipeline.config.logging.warning_interval_s) {
  // Here, before the loops start: subscribing opens the receive socket (through liblcm, its
  // self test can take seconds), which must not hold up the publishing loop. For udpm://, the
  // outlet's start-up probe has already said whether this process's multicast comes back.
  const bool receiving = outlet_.subscribe(config_.lcm.trajectory,
                                           [this](std::span<const std::uint8_t> bytes, const std::string& channel) {
                                             trajectories_.on_message(bytes, channel);
                                           });
  if (!receiving) {
    log::error(
        "LCM: this process does not receive its own multicast (its probe did not come back): trajectory messages on {} "
        "will not arrive. Under systemd the unit's IPAddressAllow= must admit this host's addresses "
        "(trajroid --unit-drop-in); otherwise check the multicast route and the firewall",
        config_.lcm.trajectory);
  }
  // An as-fast replay keeps the threads apart: there the publisher runs beside the processing
  // thread on the other core, and nothing waits for a wake-up.
  if (!pipeline_.exact && config_.realtime.publish_from_processing) pipeline_.hand_over = this;
}

bool Publisher::publish_here() {
  const std::unique_lock lock(publishing_, std::try_to_lock);
  if (!lock.owns_lock()) return false;
  publish_pending_sweeps();
  return true;
}

void Publisher::publish_sweep(const pipeline::Sweep& s) {
  const std::int64_t dequeued_ns = host::monotonic_ns();
  // A sweep filtered against another trajectory: it is the active one now (the viewers' line).
  if (trajectories_.activate(s.trajectory_id)) sender_.send_trajectory(trajectories_.active());
  sender_.send_pose(s);
  // Several LiDARs: one falling silent is said as the first sweep without it goes out.
  if (s.sensors != 0) say(health_.silent_lidars(s.silent));
  if (s.filtered) {
    sender_.send_roi(s);
    sender_.encode_points(s);
    const std::int64_t encoded_ns = host::monotonic_ns();
    sender_.send_points();
    // A partial sweep's latency (the stream's end, flushed at a stop) is the wait for the stop,
    // not the pipeline's: left out of the figures.
    if (!s.partial) {
      const std::int64_t sent_ns = host::monotonic_ns();
      const auto ms = [](std::int64_t from, std::int64_t to) { return static_cast<double>(to - from) * 1e-6; };
      // A merged sweep's last packet may be a sweep older than the one that closed the window
      // (the merge waited for a sensor): that wait is the merge's, not the processing thread's.
      const double merge_wait_ms =
          std::min(ms(0, s.merge_wait_ns), ms(s.last_packet_arrival_ns, s.closing_packet_start_ns));
      const SweepTiming timing{
          .index = s.index,
          .total_ms = ms(s.last_packet_arrival_ns, sent_ns),
          .merge_wait_ms = merge_wait_ms,
          .processing_wait_ms = ms(s.last_packet_arrival_ns, s.closing_packet_start_ns) - merge_wait_ms,
          .closing_ms = ms(s.closing_packet_start_ns, s.handed_over_ns),
          .publisher_wait_ms = ms(s.handed_over_ns, dequeued_ns),
          .encoding_ms = ms(dequeued_ns, encoded_ns),
          .sending_ms = ms(encoded_ns, sent_ns)};
      latency_.add(timing, sent_ns);
    }
    // After the kept points and outside their latency: for viewers only.
    if (config_.outputs.raw_points) sender_.send_raw_points(s);
  } else {
    // Each reason said as it first appears, its repeats summarised (log::ReasonLimiter).
    sweep_warnings_.warn(static_cast<std::uint32_t>(s.pose_status),
                         "sweep " + std::to_string(s.index) + " withheld: no valid pose (" +
                             pipeline::pose_reason(s.pose_status, s.pose_measured, s.pose_limit, config_) + ")",
                         dequeued_ns);
  }
  latency_.add_processing(static_cast<double>(s.processing_ns) * 1e-6);
}

void Publisher::publish_status(const StatusSnapshot& s) {
  // Faults said when they start and end; the state in words for systemd and the message.
  std::vector<HealthLine> lines = health_.update(s);
  const bool gnss = pipeline::uses_gnss(config_.pose_source);
  const double nan = std::numeric_limits<double>::quiet_NaN();
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
  m.state = health_.state();
  m.pose_source = std::string(pipeline::pose_source_name(config_.pose_source));
  m.pose_valid = s.pose_valid;
  m.pose_status = pipeline::pose_reason(s.pose_status, s.pose_measured, s.pose_limit, config_);
  m.pose_age_s = config_.pose_source == PoseSource::kFixed ? nan : s.pose_age_s;
  m.fix_type = gnss ? static_cast<std::int8_t>(s.fix_type) : trajroi::pose_t::NOT_APPLICABLE;
  m.h_acc_m = gnss && s.pose_age_s >= 0.0 ? s.h_acc_m : nan;
  m.recording = pipeline_.record_dir;
  m.host_minus_gnss_utc_s = s.host_minus_gnss_utc_s;
  m.gnss_time_accuracy_s = s.gnss_time_accuracy_s;
  // The first LiDAR's (status_t has one of each; the log names every sensor's).
  const StatusSnapshot::LidarFacts& lidar = s.lidar[0];
  m.host_minus_lidar_utc_s = lidar.host_minus_utc_s;
  m.rtk_solution = gnss ? s.rtk : std::int8_t{-1};
  m.lidar_pps_status = lidar.pps_status;
  m.lidar_model = lidar.model >= 0 ? std::string(vlp16::to_string(static_cast<vlp16::Model>(lidar.model))) : "";
  m.lidar_gprmc_valid = lidar.gprmc_valid;
  m.processing_ms_p50 = latency_.window_processing_ms(0.50);
  m.processing_ms_p99 = latency_.window_processing_ms(0.99);
  m.latency_ms_p50 = latency_.window_latency_ms(0.50);
  m.latency_ms_p99 = latency_.window_latency_ms(0.99);
  const auto add = [&m](std::string name, std::uint64_t value) {
    m.counter_names.push_back(std::move(name));
    m.counter_values.push_back(static_cast<std::int64_t>(value));
  };
  for (std::size_t i = 0; i < kCounterCount; ++i)
    add(std::string(counter_name(i)), s.counters[i]);
  trajectories_.add_counters(add);
  add("sweeps.late", latency_.late_sweeps());
  const CorrectionsFigures corrections = corrections_.update(s, host::monotonic_ns(), add, lines);
  m.corrections = corrections.text;
  m.correction_age_s = corrections.age_s;
  m.corrections_bytes_per_s = corrections.bytes_per_s;
  m.num_counters = static_cast<std::int32_t>(m.counter_names.size());
  sender_.send(config_.lcm.status, m);
  // Once a second too, for a viewer that starts later.
  sender_.send_trajectory(trajectories_.active());

  const double kept_pct =
      m.points_in > 0 ? 100.0 * static_cast<double>(m.points_kept) / static_cast<double>(m.points_in) : 0.0;
  log::info(
      "status: {} | sweeps {} published {} withheld {} | points in {} kept {} ({:.1f} %) | latency p50 {:.2f} p99 "
      "{:.2f} ms | drops {} | lost packets {} | {}{} | trajectory {}{}",
      m.state, m.sweeps, m.sweeps_published, m.sweeps_without_pose, m.points_in, m.points_kept, kept_pct,
      m.latency_ms_p50, m.latency_ms_p99, m.ring_drops, m.lost_packets, pose_inputs_text(s, config_), rtk_text(m),
      m.trajectory_id, recording_text());
  say(lines);
  sweep_warnings_.flush(host::monotonic_ns());
  if (!s.final) (void)notify_service("STATUS=" + health_.state());
  latency_.end_window();
  last_status_ = s;
  minute_.on_status(s, latency_);
}

std::string Publisher::rtk_text(const trajroi::status_t& m) const {
  std::string text;
  if (m.rtk_solution >= 0 && (m.rtk_solution > 0 || !m.corrections.empty()))
    text += std::string(", RTK ") + std::string(pose::to_string(static_cast<pose::RtkSolution>(m.rtk_solution)));
  if (!m.corrections.empty()) {
    text += " | corrections: " + m.corrections;
    if (std::isfinite(m.correction_age_s)) text += fmt::format(", age {:.1f} s", m.correction_age_s);
    if (std::isfinite(m.corrections_bytes_per_s)) text += fmt::format(", {:.0f} B/s", m.corrections_bytes_per_s);
  }
  return text;
}

std::string Publisher::recording_text() const {
  if (pipeline_.record_dir.empty()) return {};
  const std::uint64_t drops = pipeline_.record ? pipeline_.record->dropped() : 0;
  if (pipeline_.record_failed.load(std::memory_order_relaxed))
    return " | recording into " + pipeline_.record_dir + " STOPPED (see the error above)";
  return " | recording into " + pipeline_.record_dir +
         (drops > 0 ? " (" + std::to_string(drops) + " items dropped)" : std::string());
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
  if (!pipeline_.exact) {
    const std::lock_guard lock(publishing_);
    sender_.make_resident();
  }
  bool final_seen = false;
  for (;;) {
    pipeline_.publishing_beat.fetch_add(1, std::memory_order_relaxed);
    pollfd fds[2] = {{outlet_.incoming_fd(), POLLIN, 0}, {pipeline_.publish_wake.fd(), POLLIN, 0}};
    const bool woken = poll(fds, 2, kIdleWait_ms) > 0;
    const std::lock_guard lock(publishing_);
    if (woken) {
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
    trajectories_.take_reloads();
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
