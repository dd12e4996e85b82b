#pragma once

// The publisher's trajectory intake: trajectory messages from LCM checked (decode_trajectory)
// and SIGHUP reloads taken from the Reloader, each accepted one offered to the processing
// thread (active from its next sweep), every outcome counted for the status and logged.
#include <array>
#include <cstdint>
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
  // `reloader` may be null (no SIGHUP reloads).
  TrajectoryIntake(Pipeline& pipeline, Reloader* reloader);

  void on_message(std::span<const std::uint8_t> bytes, const std::string& channel);
  void take_reloads();
  // Its counters, by name, for the status message.
  void add_counters(const std::function<void(std::string, std::uint64_t)>& add) const;

 private:
  void offer(std::unique_ptr<pipeline::ActiveTrajectory> trajectory);

  Pipeline& pipeline_;
  Reloader* reloader_;
  pose::GlobalFrame frame_;
  std::array<std::uint64_t, kTrajectoryRejectCount> rejects_{};
  std::uint64_t accepted_ = 0, reloads_ = 0, reload_errors_ = 0;
  log::RateLimited warn_limit_;  // rejected messages: never hidden by other warnings
};

}  // namespace trajroi::daemon
