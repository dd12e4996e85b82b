// trajroi watch: listens to trajroid over LCM, prints its status each second and, given the
// run folder a replay came from, scores every published sweep against the scenario's truth:
// the sweep is decoded from the same capture, each point placed with the true pose, and the
// ground truth is the corridor matched to the sweep's published ROI chain (as the keyframe
// evaluation does). Ends at the daemon's final status (or after --seconds).
//
// Scoring a sweep takes longer than hearing it (tens of ms; far more in a sanitizer build), and
// the LCM socket's buffer holds only a few sweeps: the scoring runs on its own thread, fed by a
// queue, so that the receiving loop never falls behind and loses sweeps (it did, hearing 195 of
// 266, under ASan on a loaded 2-core machine).
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "commands.hpp"
#include "trajroi/eval/scenario_eval.hpp"
#include "trajroi/inputs/capture.hpp"
#include "trajroi/points_t.hpp"
#include "trajroi/roi/metrics.hpp"
#include "trajroi/roi_t.hpp"
#include "trajroi/sim/run_folder.hpp"
#include "trajroi/status_t.hpp"
#include "trajroi/transport/lcm_subscribe.hpp"
#include "trajroi/transport/receive_buffer.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::cli {
namespace {

namespace fs = std::filesystem;

struct WatchOptions {
  std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";
  std::string prefix = "TRAJROI";
  std::string run_dir;
  double seconds = 0.0;
};

// The run's capture decoded frame by frame, in step with the sweeps the daemon publishes.
class TruthScorer {
 public:
  explicit TruthScorer(const fs::path& dir)
      : run_(dir), source_(dir / sim::kLidarFile), decoder_(run_.calibration(), run_.stream_options()) {}

  void score(const trajroi::points_t& m, const trajroi::roi_t& roi) {
    const vlp16::Frame* frame = frame_at(static_cast<std::uint64_t>(m.sweep_index));
    if (frame == nullptr || roi.num_centres == 0) return;
    std::vector<roi::Centre> centres;
    for (std::size_t i = 0; i < roi.cx.size(); ++i) {
      centres.push_back(
          {{roi.cx[i], roi.cy[i]}, roi.theta_rad[i], roi.start_s_m + roi.spacing_m * static_cast<double>(i)});
    }
    const bool circles = roi.shape == trajroi::roi_t::CIRCULAR;
    const eval::TruthCorridor corridor(run_.trajectory(), centres, circles ? 0.0 : roi.height_m / 2.0,
                                       circles ? 2.0 * roi.radius_m : roi.width_m, !circles);
    eval::place_frame_truth(*frame, run_.truth(), run_.robot_from_lidar(), truth_points_);
    // A point is known by its time after the sweep's start (the sensor's clock: the same in the
    // capture and in the daemon, replayed or live), ring and return. Absolute times differ live:
    // the daemon anchors the sensor's clock to its own receive times, the capture to the
    // recorded ones. The keys are sorted with the point's index, so that a repeated key finds
    // its last point.
    index_.clear();
    for (std::size_t i = 0; i < frame->points.size(); ++i) {
      const auto& p = frame->points[i];
      index_.emplace_back(point_key(p.time_offset_ns, p.ring, static_cast<std::uint8_t>(p.return_type)),
                          static_cast<std::uint32_t>(i));
    }
    std::sort(index_.begin(), index_.end());
    roi::IndexVector kept;
    for (std::size_t k = 0; k < m.x.size(); ++k) {
      if (m.time_offset_ns[k] < 0) continue;  // never a capture point's
      const std::uint64_t key =
          point_key(static_cast<std::uint32_t>(m.time_offset_ns[k]), static_cast<std::uint8_t>(m.ring[k]),
                    static_cast<std::uint8_t>(m.return_type[k]));
      const auto after = std::upper_bound(index_.begin(), index_.end(), std::pair{key, ~std::uint32_t{0}});
      if (after != index_.begin() && std::prev(after)->first == key) kept.push_back(std::prev(after)->second);
    }
    std::sort(kept.begin(), kept.end());
    std::vector<std::uint8_t> truth(truth_points_.size());
    for (std::size_t i = 0; i < truth.size(); ++i)
      truth[i] = corridor.contains(truth_points_[i].x, truth_points_[i].y) ? 1 : 0;
    const roi::Confusion c = roi::confusion(kept, truth);
    total_.tp += c.tp;
    total_.fp += c.fp;
    total_.fn += c.fn;
    total_.tn += c.tn;
    ++scored_;
  }
  [[nodiscard]] const roi::Confusion& total() const noexcept { return total_; }
  [[nodiscard]] std::size_t scored() const noexcept { return scored_; }

 private:
  static std::uint64_t point_key(std::uint32_t time_offset_ns, std::uint8_t ring, std::uint8_t return_type) noexcept {
    return (std::uint64_t{time_offset_ns} << 16) | (std::uint64_t{ring} << 8) | return_type;
  }

  const vlp16::Frame* frame_at(std::uint64_t index) {
    struct Keep final : vlp16::FrameSink {
      std::deque<vlp16::Frame>* frames;
      void on_frame(const vlp16::Frame& f) override { frames->push_back(f); }
    } keep;
    keep.frames = &frames_;
    while (!frames_.empty() && frames_.front().index < index)
      frames_.pop_front();
    while ((frames_.empty() || frames_.back().index < index) && !ended_) {
      ended_ = capture_.step(keep) != vlp16::PacketSource::Next::kDatagram;
    }
    for (const auto& f : frames_) {
      if (f.index == index) return &f;
    }
    return nullptr;
  }

  eval::ScenarioRun run_;
  vlp16::PcapSource source_;
  vlp16::StreamDecoder decoder_;
  inputs::CaptureDecoder capture_{source_, decoder_};
  std::deque<vlp16::Frame> frames_;
  bool ended_ = false;
  std::vector<roi::PointXYZd> truth_points_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> index_;
  roi::Confusion total_{};
  std::size_t scored_ = 0;
};

// Sweeps heard wait here for the scoring thread. At most kMaxWaiting wait (a minute of sweeps at
// 10 Hz, a few hundred MB): a scorer further behind than that has the newer sweeps counted as
// not scored, never the receiving loop held up.
class ScoringThread {
 public:
  static constexpr std::size_t kMaxWaiting = 600;

  explicit ScoringThread(TruthScorer& scorer) : scorer_(scorer), thread_([this] { run(); }) {}
  ScoringThread(const ScoringThread&) = delete;
  ScoringThread& operator=(const ScoringThread&) = delete;
  ~ScoringThread() { finish(); }

  // False when kMaxWaiting sweeps already wait.
  bool offer(const trajroi::points_t& points, const trajroi::roi_t& roi) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (waiting_.size() >= kMaxWaiting) return false;
      waiting_.emplace_back(points, roi);
    }
    wake_.notify_one();
    return true;
  }

  // Scores every sweep still waiting, then ends the thread.
  void finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finishing_ = true;
    }
    wake_.notify_one();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return finishing_ || !waiting_.empty(); });
      if (waiting_.empty()) return;
      const std::pair<trajroi::points_t, trajroi::roi_t> sweep = std::move(waiting_.front());
      waiting_.pop_front();
      lock.unlock();
      scorer_.score(sweep.first, sweep.second);
      lock.lock();
    }
  }

  TruthScorer& scorer_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::pair<trajroi::points_t, trajroi::roi_t>> waiting_;
  bool finishing_ = false;
  std::thread thread_;  // last: started once the members above exist
};

class Watcher {
 public:
  explicit Watcher(const WatchOptions& o) : o_(o), lcm_(transport::without_receive_buffer(o.url)) {
    if (!lcm_.good()) throw std::runtime_error("LCM: cannot open '" + o.url + "'");
    if (!o.run_dir.empty()) {
      scorer_ = std::make_unique<TruthScorer>(o.run_dir);
      scoring_ = std::make_unique<ScoringThread>(*scorer_);
    }
    trajroi::transport::subscribe<&Watcher::on_points>(lcm_, o.prefix + "_POINTS", this);
    trajroi::transport::subscribe<&Watcher::on_roi>(lcm_, o.prefix + "_ROI", this);
    trajroi::transport::subscribe<&Watcher::on_status>(lcm_, o.prefix + "_STATUS", this);
    take_receive_buffer();
  }

  void run() {
    const auto start = std::chrono::steady_clock::now();
    while (!done_) {
      lcm_.handleTimeout(100);
      if (o_.seconds > 0.0 &&
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > o_.seconds) {
        break;
      }
    }
    std::printf("trajroi watch: %zu sweeps heard", points_heard_);
    if (last_) {
      const auto& s = *last_;
      std::printf(" of %lld published (%lld withheld without a valid pose); points in %lld, kept %lld; ring drops %lld",
                  static_cast<long long>(s.sweeps_published), static_cast<long long>(s.sweeps_without_pose),
                  static_cast<long long>(s.points_in), static_cast<long long>(s.points_kept),
                  static_cast<long long>(s.ring_drops));
    }
    std::printf("\n");
    // The daemon's latency over the seconds of this watch that published sweeps (a second with
    // none has no figure, not 0 ms).
    if (window_p50_ms_.empty()) {
      std::printf("trajroi watch: latency: no second with a published sweep heard\n");
    } else {
      std::vector<double> p50 = window_p50_ms_;
      std::nth_element(p50.begin(), p50.begin() + static_cast<std::ptrdiff_t>(p50.size() / 2), p50.end());
      std::printf(
          "trajroi watch: latency over the %zu seconds with sweeps (last packet received → points published): "
          "p50 %.3f ms (the median second's), p99 %.3f ms (the worst second's)\n",
          window_p50_ms_.size(), p50[p50.size() / 2], *std::max_element(window_p99_ms_.begin(), window_p99_ms_.end()));
    }
    if (last_) std::printf("trajroi watch: state at the end: %s\n", last_->state.c_str());
    if (!scorer_) {
      std::printf(
          "trajroi watch: not scored: --run RUN_DIR (the simulated run being replayed) adds precision, recall and "
          "accuracy of the kept points against the run's truth\n");
    }
    if (scoring_) scoring_->finish();
    if (not_scored_ > 0) {
      std::printf("trajroi watch: %zu sweeps heard but not scored: the scorer was %zu sweeps behind\n", not_scored_,
                  ScoringThread::kMaxWaiting);
    }
    if (scorer_ && scorer_->scored() > 0) {
      const roi::Confusion& c = scorer_->total();
      std::printf(
          "trajroi watch: against the scenario's truth over %zu sweeps: precision %.4f, recall %.4f, accuracy %.4f "
          "(TP %llu, FP %llu, FN %llu, TN %llu)\n",
          scorer_->scored(), c.precision(), c.recall(), c.accuracy(), static_cast<unsigned long long>(c.tp),
          static_cast<unsigned long long>(c.fp), static_cast<unsigned long long>(c.fn),
          static_cast<unsigned long long>(c.tn));
    }
  }

 private:
  void take_receive_buffer() {
    int bytes = 0;
    std::uint16_t port = 0;
    if (!transport::udpm_receive_options(o_.url, bytes, port) || bytes <= 0) return;
    (void)lcm_.getFileno();  // liblcm makes its receive socket now
    const transport::ReceiveBuffer buffer = transport::set_udp_receive_buffers(port, bytes);
    if (buffer.capped()) std::fprintf(stderr, "%s\n", transport::describe_capped("trajroi watch", buffer).c_str());
  }

  void on_points(const lcm::ReceiveBuffer*, const std::string&, const trajroi::points_t* m) {
    ++points_heard_;
    const auto roi = rois_.find(m->sweep_index);
    if (scoring_ && roi != rois_.end() && !scoring_->offer(*m, roi->second)) ++not_scored_;
    rois_.erase(rois_.begin(), rois_.upper_bound(m->sweep_index));
  }
  void on_roi(const lcm::ReceiveBuffer*, const std::string&, const trajroi::roi_t* m) { rois_[m->sweep_index] = *m; }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const trajroi::status_t* m) {
    if (last_ && m->sweeps_published > last_->sweeps_published) {
      window_p50_ms_.push_back(m->latency_ms_p50);
      window_p99_ms_.push_back(m->latency_ms_p99);
    }
    last_ = *m;
    std::printf(
        "status %6.1f s: %s | sweeps %lld published %lld withheld %lld | kept %lld of %lld | latency p99 %.2f ms | "
        "drops %lld\n",
        m->uptime_s, m->state.c_str(), static_cast<long long>(m->sweeps), static_cast<long long>(m->sweeps_published),
        static_cast<long long>(m->sweeps_without_pose), static_cast<long long>(m->points_kept),
        static_cast<long long>(m->points_in), m->latency_ms_p99, static_cast<long long>(m->ring_drops));
    std::fflush(stdout);
    if (m->final_status) done_ = true;
  }

  WatchOptions o_;
  lcm::LCM lcm_;
  std::unique_ptr<TruthScorer> scorer_;
  std::unique_ptr<ScoringThread> scoring_;  // after scorer_: it ends first
  std::map<std::int64_t, trajroi::roi_t> rois_;
  std::optional<trajroi::status_t> last_;
  std::vector<double> window_p50_ms_, window_p99_ms_;  // each status second that published sweeps
  std::size_t points_heard_ = 0;
  std::size_t not_scored_ = 0;
  bool done_ = false;
};

}  // namespace

void add_watch_command(CLI::App& app) {
  auto o = std::make_shared<WatchOptions>();
  CLI::App* cmd = app.add_subcommand("watch", "Listen to trajroid over LCM; score a replayed run against its truth");
  cmd->add_option("--lcm-url", o->url,
                  "LCM provider URL (recv_buf_size is taken past net.core.rmem_max when run as root)")
      ->capture_default_str();
  cmd->add_option("--channel-prefix", o->prefix, "Channels <prefix>_POINTS, _ROI, _STATUS")->capture_default_str();
  cmd->add_option("--run", o->run_dir, "The run folder being replayed (scores precision and recall)");
  cmd->add_option("--seconds", o->seconds, "Stop after this long (0: at the daemon's final status)")
      ->capture_default_str();
  cmd->callback([o] { Watcher(*o).run(); });
}

}  // namespace trajroi::cli
