#pragma once

// The publisher's trajectory intake: trajectory messages from LCM checked (decode_trajectory)
// and SIGHUP reloads taken from the Reloader, each accepted one offered to the processing
// thread (active from its next sweep), every outcome counted for the status and logged.
// Every accepted trajectory gets an id above every earlier one (the configured file's at start
// is 0): a message's own id when it is above them, else the next; a SIGHUP reload the next. So
// points_t and roi_t tell which trajectory each sweep was filtered against.
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "log.hpp"
#include "pipeline.hpp"
#include "reload.hpp"
#include "trajroi/daemon/messages.hpp"
#include "trajroi/pose/geodetic.hpp"

namespace trajroi::daemon {

class TrajectoryIntake {
 public:
  // `reloader` may be null (no SIGHUP reloads). `initial`: the trajectory active at start.
  TrajectoryIntake(Pipeline& pipeline, Reloader* reloader, const pipeline::ActiveTrajectory& initial);

  void on_message(std::span<const std::uint8_t> bytes, const std::string& channel);
  void take_reloads();
  // The active trajectory as far as the sweeps tell: the one active at start, then each the
  // processor took up (activate).
  [[nodiscard]] const pipeline::ActiveTrajectory& active() const noexcept { return known_.front(); }
  // A sweep was filtered against trajectory `id`: it becomes active() (the earlier ones are
  // forgotten). False when it already was, or is not known.
  bool activate(std::int32_t id);
  // Its counters, by name, for the status message.
  void add_counters(const std::function<void(std::string, std::uint64_t)>& add) const;

 private:
  void offer(std::unique_ptr<pipeline::ActiveTrajectory> trajectory);
  // The id of the next accepted trajectory: `wanted` when above every earlier id.
  std::int32_t next_id(std::int32_t wanted);

  Pipeline& pipeline_;
  Reloader* reloader_;
  // Copies of the active trajectory (front) and of those offered since, by id ascending: the
  // processor owns the ones it filters with.
  std::deque<pipeline::ActiveTrajectory> known_;
  pose::GlobalFrame frame_;
  std::array<std::uint64_t, kTrajectoryRejectCount> rejects_{};
  std::uint64_t accepted_ = 0, reloads_ = 0, reload_errors_ = 0;
  std::int32_t last_id_ = 0;     // the configured file's at start
  log::RateLimited warn_limit_;  // rejected messages: never hidden by other warnings
};

}  // namespace trajroi::daemon
