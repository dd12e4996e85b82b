#include "reload.hpp"

#include <pthread.h>

#include "pipeline.hpp"

namespace trajroi::daemon {

Reloader::Reloader(TrajectorySource source, const EventFd& done)
    : source_(std::move(source)), done_(done), thread_([this] { run(); }) {}

Reloader::~Reloader() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_one();
  thread_.join();
}

void Reloader::request() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++requests_;
  }
  cv_.notify_one();
}

std::vector<Reloader::Result> Reloader::take() {
  std::vector<Result> done;
  std::lock_guard<std::mutex> lock(mutex_);
  done.swap(results_);
  return done;
}

void Reloader::run() {
  pthread_setname_np(pthread_self(), "trajroid-reload");
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return requests_ > 0 || stop_; });
    if (stop_) return;
    requests_ = 0;
    lock.unlock();
    Result r;
    try {
      r.trajectory = load_trajectory(source_);
    } catch (const std::exception& e) {
      r.error = e.what();
    }
    lock.lock();
    results_.push_back(std::move(r));
    done_.notify();
  }
}

}  // namespace trajroi::daemon
