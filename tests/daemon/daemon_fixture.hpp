#pragma once

// Runs trajroid (TRAJROID, set by CMake) as a child process on a scenario simulated once per
// test program, and listens to it over LCM on loopback. Each test uses its own channel names,
// so tests running side by side do not hear each other.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "trajroi/inputs/capture.hpp"
#include "trajroi/points_t.hpp"
#include "trajroi/pose_t.hpp"
#include "trajroi/roi_t.hpp"
#include "trajroi/status_t.hpp"
#include "trajroi/trajectory_t.hpp"
#include "trajroi/transport/lcm_subscribe.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace daemon_test {

namespace fs = std::filesystem;

inline const char* kTestLcmUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline int run_command(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Simulates `scenario` into a temporary run folder (removed at exit).
inline fs::path simulate(const std::string& scenario, const std::string& tag) {
  static std::vector<fs::path> made;
  const fs::path d = fs::temp_directory_path() / ("trajroid_test_" + tag + "_" + std::to_string(::getpid()));
  const std::string cmd =
      std::string(TRAJROI_CLI) + " sim --quiet --scenario " + scenario + " --out " + d.string() + " >/dev/null";
  if (run_command(cmd) != 0) throw std::runtime_error("cannot simulate the test scenario: " + cmd);
  if (made.empty()) {
    std::atexit([] {
      std::error_code ignored;
      for (const fs::path& p : made)
        fs::remove_all(p, ignored);
    });
  }
  made.push_back(d);
  return d;
}

// The scenario run most tests replay (tests/daemon/corridor.yaml), simulated on first use.
inline const fs::path& corridor_run() {
  static const fs::path dir = simulate(TRAJROI_TEST_SCENARIO, "run");
  return dir;
}

// The capture decoded as the daemon decodes it (the test scenarios' ranges), sweep by sweep.
inline std::vector<trajroi::vlp16::Frame> decode_capture(const fs::path& pcap) {
  struct Collect final : trajroi::vlp16::FrameSink {
    std::vector<trajroi::vlp16::Frame> frames;
    void on_frame(const trajroi::vlp16::Frame& f) override { frames.push_back(f); }
  } sink;
  trajroi::vlp16::StreamOptions options;
  options.decode.min_range_m = 0.5;
  options.decode.max_range_m = 60.0;
  trajroi::vlp16::StreamDecoder decoder(trajroi::vlp16::Calibration::vlp16_default(), options);
  trajroi::vlp16::PcapSource source(pcap);
  trajroi::inputs::CaptureDecoder(source, decoder).run(sink);
  return std::move(sink.frames);
}

// A running trajroid (or, with `program`, another tool: its stdout goes to the file too).
class Child {
 public:
  // `environment`: NAME=value entries added to the child's environment.
  Child(const std::vector<std::string>& args, const fs::path& stderr_file,
        const std::vector<std::string>& environment = {}) {
    start(TRAJROID, args, stderr_file, environment, false);
  }
  Child(const std::string& program, const std::vector<std::string>& args, const fs::path& output_file) {
    start(program, args, output_file, {}, true);
  }
  ~Child() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  void signal(int sig) const { kill(pid_, sig); }
  [[nodiscard]] bool running() { return !reaped(); }
  [[nodiscard]] pid_t pid() const noexcept { return pid_; }
  // The exit code, or -1 when it did not exit within the timeout (then it is killed).
  int wait(std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      if (reaped()) return code_;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return -1;
  }

 private:
  bool reaped() {
    int status = 0;
    if (!exited_ && waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    return exited_;
  }

  void start(const std::string& program, const std::vector<std::string>& args, const fs::path& output_file,
             const std::vector<std::string>& environment, bool stdout_too) {
    pid_ = fork();
    if (pid_ == 0) {
      std::freopen(output_file.c_str(), "w", stderr);
      if (stdout_too) dup2(fileno(stderr), STDOUT_FILENO);
      for (const std::string& e : environment)
        putenv(strdup(e.c_str()));
      std::vector<std::string> copy = args;
      copy.insert(copy.begin(), program);
      std::vector<char*> argv;
      for (std::string& a : copy)
        argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(program.c_str(), argv.data());
      _exit(127);
    }
  }

  pid_t pid_ = -1;
  bool exited_ = false;
  int code_ = -1;
};

// Everything trajroid publishes on a test's channels.
class Listener {
 public:
  explicit Listener(const std::string& prefix) : prefix_(prefix), lcm_(kTestLcmUrl) {
    trajroi::transport::subscribe<&Listener::on_points>(lcm_, prefix + "_POINTS", this);
    trajroi::transport::subscribe<&Listener::on_pose>(lcm_, prefix + "_POSE", this);
    trajroi::transport::subscribe<&Listener::on_roi>(lcm_, prefix + "_ROI", this);
    trajroi::transport::subscribe<&Listener::on_status>(lcm_, prefix + "_STATUS", this);
    thread_ = std::thread([this] {
      while (!stop_)
        lcm_.handleTimeout(20);
    });
  }
  ~Listener() {
    stop_ = true;
    thread_.join();
  }
  [[nodiscard]] bool good() { return lcm_.good(); }
  void publish_trajectory(const trajroi::trajectory_t& m) { lcm_.publish(prefix_ + "_TRAJECTORY", &m); }

  std::mutex mutex;
  std::map<std::int64_t, trajroi::points_t> points;
  std::map<std::int64_t, trajroi::pose_t> poses;
  std::map<std::int64_t, trajroi::roi_t> rois;
  std::vector<trajroi::status_t> statuses;
  std::vector<std::int64_t> arrival_order;  // points sweep indices as they came

  template <typename Pred>
  bool wait_for(Pred pred, std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (pred()) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

 private:
  void on_points(const lcm::ReceiveBuffer*, const std::string&, const trajroi::points_t* m) {
    std::lock_guard<std::mutex> lock(mutex);
    points[m->sweep_index] = *m;
    arrival_order.push_back(m->sweep_index);
  }
  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const trajroi::pose_t* m) {
    std::lock_guard<std::mutex> lock(mutex);
    poses[m->sweep_index] = *m;
  }
  void on_roi(const lcm::ReceiveBuffer*, const std::string&, const trajroi::roi_t* m) {
    std::lock_guard<std::mutex> lock(mutex);
    rois[m->sweep_index] = *m;
  }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const trajroi::status_t* m) {
    std::lock_guard<std::mutex> lock(mutex);
    statuses.push_back(*m);
  }

  std::string prefix_;
  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

inline std::int64_t counter(const trajroi::status_t& s, const std::string& name) {
  for (int i = 0; i < s.num_counters; ++i) {
    if (s.counter_names[static_cast<std::size_t>(i)] == name) return s.counter_values[static_cast<std::size_t>(i)];
  }
  ADD_FAILURE() << "no counter '" << name << "' in status_t";
  return -1;
}

}  // namespace daemon_test
