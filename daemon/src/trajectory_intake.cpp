#include "trajectory_intake.hpp"

namespace trajroi::daemon {

TrajectoryIntake::TrajectoryIntake(Pipeline& pipeline, Reloader* reloader, const pipeline::ActiveTrajectory& initial)
    : pipeline_(pipeline),
      reloader_(reloader),
      known_{initial},
      frame_(pose::GlobalFrame::local_cartesian(pipeline.config.origin)),
      warn_limit_(pipeline.config.logging.warning_interval_s) {}

void TrajectoryIntake::offer(std::unique_ptr<pipeline::ActiveTrajectory> trajectory) {
  known_.push_back(*trajectory);
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
  const std::int32_t sent = check.trajectory->id;
  check.trajectory->id = next_id(sent);
  const std::string renumbered = check.trajectory->id == sent ? std::string()
                                                              : " (its message said id " + std::to_string(sent) +
                                                                    ", not above the last id given: each accepted "
                                                                    "trajectory gets an id above every earlier one)";
  log::info("trajectory {} accepted from {}: {} waypoints, {:.1f} m; active from the next sweep{}",
            check.trajectory->id, channel, check.trajectory->trajectory.waypoints().size(),
            check.trajectory->trajectory.length_m(), renumbered);
  offer(std::move(check.trajectory));
}

bool TrajectoryIntake::activate(std::int32_t id) {
  if (known_.front().id == id) return false;
  std::size_t i = 1;
  while (i < known_.size() && known_[i].id != id)
    ++i;
  if (i == known_.size()) return false;
  known_.erase(known_.begin(), known_.begin() + static_cast<std::ptrdiff_t>(i));
  return true;
}

std::int32_t TrajectoryIntake::next_id(std::int32_t wanted) {
  last_id_ = wanted > last_id_ ? wanted : last_id_ + 1;
  return last_id_;
}

void TrajectoryIntake::take_reloads() {
  if (reloader_ == nullptr) return;
  for (Reloader::Result& r : reloader_->take()) {
    if (r.trajectory) {
      r.trajectory->id = next_id(0);
      ++reloads_;
      log::info("SIGHUP: trajectory {} reloaded from {}: {} waypoints, {:.1f} m; active from the next sweep",
                r.trajectory->id, reloader_->file().string(), r.trajectory->trajectory.waypoints().size(),
                r.trajectory->trajectory.length_m());
      offer(std::move(r.trajectory));
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
