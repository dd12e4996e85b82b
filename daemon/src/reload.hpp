#pragma once

// SIGHUP reloads: the trajectory file is read and checked on a thread of its own, off the
// publishing thread (a file of a million waypoints must not hold up publication). Requests
// that come while a file is being read are served by one more read afterwards.
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "trajroi/daemon/trajectory_file.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"

namespace trajroi::daemon {

class EventFd;

class Reloader {
 public:
  struct Result {
    std::unique_ptr<pipeline::ActiveTrajectory> trajectory;  // or why not:
    std::string error;
  };
  // Starts the thread; `done` is notified when a result is ready.
  Reloader(TrajectorySource source, const EventFd& done);
  ~Reloader();  // stops and joins the thread
  Reloader(const Reloader&) = delete;
  Reloader& operator=(const Reloader&) = delete;

  void request();
  // The results ready (the mutex is held for a vector swap only).
  [[nodiscard]] std::vector<Result> take();
  [[nodiscard]] const std::filesystem::path& file() const noexcept { return source_.file; }

 private:
  void run();
  TrajectorySource source_;
  const EventFd& done_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::uint64_t requests_ = 0;
  bool stop_ = false;
  std::vector<Result> results_;
  std::thread thread_;
};

}  // namespace trajroi::daemon
