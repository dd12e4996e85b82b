#include "trajectory_intake.hpp"

namespace trajroi::daemon {

TrajectoryIntake::TrajectoryIntake(Pipeline& pipeline, Reloader* reloader)
    : pipeline_(pipeline),
      reloader_(reloader),
      frame_(pose::GlobalFrame::local_cartesian(pipeline.config.origin)),
      warn_limit_(pipeline.config.logging.warning_interval_s) {}

void TrajectoryIntake::offer(std::unique_ptr<pipeline::ActiveTrajectory> trajectory) {
  const bool pushed = pipeline_.trajectories_in.try_push(
      [&trajectory](TrajectoryItem& slot) { slot.trajectory = std::move(trajectory); });
  if (pushed) pipeline_.process_wake.notify();
}

void TrajectoryIntake::on_message(std::span<const std::uint8_t> bytes, const std::string& channel) {
  TrajectoryCheck check = decode_trajectory(bytes.data(), bytes.size(), frame_);
  if (check.reason != TrajectoryReject::kNone) {
    ++rejects_[static_cast<std::size_t>(check.reason)];
    log::warn_limited(warn_limit_, "trajectory on " + channel + " rejected: " + std::string(to_string(check.reason)) +
                                       " (" + check.detail + "); the active one stays");
    return;
  }
  ++accepted_;
  log::info("trajectory {} accepted: {} waypoints, {:.1f} m; active from the next sweep", check.trajectory->id,
            check.trajectory->trajectory.waypoints().size(), check.trajectory->trajectory.length_m());
  offer(std::move(check.trajectory));
}

void TrajectoryIntake::take_reloads() {
  if (reloader_ == nullptr) return;
  for (Reloader::Result& r : reloader_->take()) {
    if (r.trajectory) {
      offer(std::move(r.trajectory));
      ++reloads_;
      log::info("SIGHUP: trajectory reloaded from {}; active from the next sweep", reloader_->file().string());
    } else {
      ++reload_errors_;
      log::error("SIGHUP: trajectory not reloaded, the active one stays: {}", r.error);
    }
  }
}

void TrajectoryIntake::add_counters(const std::function<void(std::string, std::uint64_t)>& add) const {
  for (std::size_t i = 1; i < kTrajectoryRejectCount; ++i)
    add("trajectory.rejected: " + std::string(to_string(static_cast<TrajectoryReject>(i))), rejects_[i]);
  add("trajectory.accepted", accepted_);
  add("trajectory.reloads", reloads_);
  add("trajectory.reload_errors", reload_errors_);
}

}  // namespace trajroi::daemon
