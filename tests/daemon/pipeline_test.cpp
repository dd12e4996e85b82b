// trajroid's thread loops driven in process: a fake input source per stream (the run's items
// as the daemon's merger orders them) and a fake outlet that keeps every published message.
// No binary, no sockets, no LCM: the input threads, the processing thread and the publisher
// run as in the daemon (run by the README's test command under ThreadSanitizer too).
#include "pipeline.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "daemon_fixture.hpp"
#include "outlet.hpp"
#include "reload.hpp"
#include "resident.hpp"
#include "trajroi/daemon/config.hpp"
#include "trajroi/eval/scenario_eval.hpp"
#include "trajroi/inputs/pacer.hpp"
#include "trajroi/inputs/recorded_input.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/points_t.hpp"
#include "trajroi/status_t.hpp"
#include "trajroid.hpp"

namespace {

using namespace daemon_test;
using trajroi::daemon::DaemonConfig;
using trajroi::daemon::Pipeline;
using trajroi::pipeline::SweepProcessor;
namespace inputs = trajroi::inputs;

struct Item {
  inputs::Stream stream;
  std::int64_t t_ns;
  std::vector<std::uint8_t> bytes;
};

std::vector<Item> run_items(inputs::RunStreams streams) {
  std::vector<Item> out;
  inputs::RunMerger merger(corridor_run(), streams);
  inputs::InputItem item;
  while (merger.next(item))
    out.push_back({item.stream, item.receive_ns, {item.bytes.begin(), item.bytes.end()}});
  return out;
}

// Hands out its items, then ends; says a notice and an error first (both must be logged and
// passed over, never stop the lane).
class FakeInput final : public inputs::InputSource {
 public:
  // `rate` > 0 paces the items by their times (as sensors would), 0: as fast as possible.
  explicit FakeInput(std::vector<Item> items, double rate = 0.0) : items_(std::move(items)), pacer_(rate) {}
  Next next(inputs::InputItem& item, std::chrono::milliseconds) override {
    if (step_ == 0) {
      ++step_;
      return Next::kNotice;
    }
    if (step_ == 1) {
      ++step_;
      ++counters_.errors;
      return Next::kError;
    }
    if (next_ == items_.size()) return Next::kEnd;
    const Item& i = items_[next_++];
    inputs::Pacer::sleep_until(pacer_.due_ns(i.t_ns));
    item.stream = i.stream;
    item.receive_ns = i.t_ns;
    item.bytes = i.bytes;
    ++counters_.items;
    return Next::kItem;
  }
  [[nodiscard]] bool ready() const noexcept override { return next_ < items_.size(); }
  [[nodiscard]] const inputs::Notice& notice() const noexcept override { return notice_; }
  [[nodiscard]] const std::string& error() const noexcept override { return error_; }
  [[nodiscard]] inputs::InputCounters counters() const noexcept override { return counters_; }
  [[nodiscard]] std::string describe() const override { return "fake input"; }

 private:
  std::vector<Item> items_;
  inputs::Pacer pacer_;
  std::size_t next_ = 0;
  int step_ = 0;
  inputs::Notice notice_{inputs::Notice::Level::kInfo, "fake input: a notice"};
  std::string error_ = "a fake error";
  inputs::InputCounters counters_;
};

class FakeOutlet final : public trajroi::daemon::Outlet {
 public:
  FakeOutlet() = default;
  // Takes `delay` to send each message on `slow_channel` (a slow network or subscriber).
  FakeOutlet(std::string slow_channel, std::chrono::milliseconds delay)
      : slow_channel_(std::move(slow_channel)), delay_(delay) {}
  void publish(const std::string& channel, std::span<const std::uint8_t> bytes) override {
    if (channel == slow_channel_) std::this_thread::sleep_for(delay_);
    std::array<char, 16> name{};
    pthread_getname_np(pthread_self(), name.data(), name.size());
    std::lock_guard<std::mutex> lock(mutex_);
    messages_[channel].emplace_back(bytes.begin(), bytes.end());
    senders_[channel].emplace_back(name.data());
  }
  bool subscribe(const std::string&, Handler) override { return true; }
  [[nodiscard]] int incoming_fd() const noexcept override { return -1; }
  void handle_incoming() override {}
  std::vector<std::vector<std::uint8_t>> messages(const std::string& channel) {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_[channel];
  }
  // The name of the thread that published each message on `channel`, in order.
  std::vector<std::string> senders(const std::string& channel) {
    std::lock_guard<std::mutex> lock(mutex_);
    return senders_[channel];
  }

 private:
  std::string slow_channel_;
  std::chrono::milliseconds delay_{0};
  std::mutex mutex_;
  std::map<std::string, std::vector<std::vector<std::uint8_t>>> messages_;
  std::map<std::string, std::vector<std::string>> senders_;
};

template <typename Message>
Message decode(const std::vector<std::uint8_t>& bytes) {
  Message m;
  EXPECT_GE(m.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  return m;
}

// The sweeps SweepProcessor makes from the run by itself, in the daemon's order.
std::map<std::int64_t, std::size_t> reference_kept(const DaemonConfig& config) {
  struct Count final : trajroi::pipeline::SweepSink {
    std::map<std::int64_t, std::size_t> kept;
    void on_sweep(trajroi::pipeline::Sweep& s) override {
      if (s.filtered) kept[static_cast<std::int64_t>(s.index)] = s.size();
    }
  } sink;
  trajroi::pipeline::SweepProcessor processor(
      config, trajroi::daemon::load_trajectory(trajroi::daemon::TrajectorySource::from(config)));
  for (const Item& i : run_items({})) {
    processor.process({i.stream, i.bytes, i.t_ns}, sink);
  }
  processor.flush(sink);
  return sink.kept;
}

TEST(Pipeline, ThreeFakeInputLanesThroughTheThreadsGiveTheProcessorsOwnSweeps) {
  const DaemonConfig config = trajroi::daemon::load_daemon_config(corridor_run() / "trajroid.yaml");
  // As live: one lane per stream (the lidar, the GNSS and the IMU source each with its thread).
  // exact: a full ring waits (an as-fast-as-possible replay), so nothing may be dropped.
  Pipeline pipeline(config, /*exact=*/true, /*record=*/false);
  // Paced at 5x real time, as three sensors would deliver (each lane its own pacer), slow
  // enough for ThreadSanitizer's processing to keep up.
  constexpr double kRate = 5.0;
  pipeline.add_input(std::make_unique<FakeInput>(run_items({true, false, false}), kRate), 64, "test-lidar", {});
  pipeline.add_input(std::make_unique<FakeInput>(run_items({false, true, false}), kRate), 64, "test-gnss", {});
  pipeline.add_input(std::make_unique<FakeInput>(run_items({false, false, true}), kRate), 64, "test-imu", {});
  trajroi::pipeline::SweepProcessor processor(
      config, trajroi::daemon::load_trajectory(trajroi::daemon::TrajectorySource::from(config)));
  FakeOutlet outlet;
  trajroi::daemon::RunOptions options;
  options.replay = corridor_run();  // said in the status message only
  EXPECT_EQ(trajroi::daemon::run_pipeline(pipeline, processor, outlet, options, /*signals=*/false), 0);

  // Three lanes interleave by their own pace, so the pose may see an item a little later than
  // the merged order would give it: the sweeps and their sizes are compared, not their bytes.
  const auto reference = reference_kept(config);
  ASSERT_GT(reference.size(), 100u);
  std::map<std::int64_t, std::size_t> published;
  for (const auto& bytes : outlet.messages(config.lcm.points)) {
    const auto m = decode<trajroi::points_t>(bytes);
    published[m.sweep_index] = static_cast<std::size_t>(m.num_points);
  }
  // A pose sample that reaches the processor a packet later than in the merged order moves a
  // few points across the ROI's edge: sweeps within 1 % of the reference's kept count.
  std::size_t close = 0;
  for (const auto& [index, kept] : reference) {
    const auto it = published.find(index);
    if (it != published.end()) {
      const double d = static_cast<double>(it->second) - static_cast<double>(kept);
      close += std::abs(d) <= 0.01 * static_cast<double>(kept) ? 1U : 0U;
    }
  }
  EXPECT_GE(static_cast<double>(close), 0.95 * static_cast<double>(reference.size()));
  EXPECT_GE(static_cast<double>(published.size()), 0.98 * static_cast<double>(reference.size()));

  const auto statuses = outlet.messages(config.lcm.status);
  ASSERT_FALSE(statuses.empty());
  const auto last = decode<trajroi::status_t>(statuses.back());
  EXPECT_TRUE(last.final_status);
  EXPECT_EQ(last.ring_drops, 0);
  EXPECT_EQ(counter(last, "lidar.source_errors"), 3) << "one error said by each fake lane";
  EXPECT_EQ(last.sweeps_published, static_cast<std::int64_t>(published.size()));
}

using test_memory::resident;
using test_memory::resident_capacity;

// Live (and a timed replay): the sweeps' arrays and a LiDAR lane's ring of packets decoded
// ahead are allocated and resident before the first datagram, so a flood or a busier scene
// grows neither the memory nor the page faults. A serial lane has no decode-ahead ring.
TEST(Pipeline, SweepsAndTheDecodeAheadRingAreResidentFromTheStart) {
  const DaemonConfig config = trajroi::daemon::load_daemon_config(corridor_run() / "trajroid.yaml");
  Pipeline pipeline(config, /*exact=*/false, /*record=*/false);
  const auto& lidar = pipeline.add_input(std::make_unique<FakeInput>(std::vector<Item>{}), 16, "test-lidar", {});
  const auto& gnss =
      pipeline.add_input(std::make_unique<FakeInput>(std::vector<Item>{}), 16, "test-gnss", {}, Pipeline::Lidar::kNone);
  EXPECT_EQ(gnss.decoded, nullptr);
  ASSERT_NE(lidar.decoded, nullptr);
  std::size_t packets = 0;
  while (lidar.decoded->try_push([&](trajroi::vlp16::DecodedPacket& d) {
    EXPECT_EQ(d.count, 0U);
    EXPECT_EQ(d.points.size(), trajroi::vlp16::kPointsPerPacket);
    EXPECT_TRUE(resident(&d, sizeof d)) << "decoded packet " << packets;
  }))
    ++packets;
  EXPECT_EQ(packets, lidar.decoded->capacity());
  std::size_t sweeps = 0;
  while (pipeline.sweeps.push([&](trajroi::pipeline::Sweep& s) {
    EXPECT_EQ(s.size(), 0U);
    EXPECT_GE(s.x.capacity(), config.buffers.max_points_per_sweep);
    const bool all = resident_capacity(s.x) && resident_capacity(s.y) && resident_capacity(s.z) &&
                     resident_capacity(s.intensity) && resident_capacity(s.ring) && resident_capacity(s.return_type) &&
                     resident_capacity(s.time_offset_ns);
    EXPECT_TRUE(all) << "sweep slot " << sweeps;
  }))
    ++sweeps;
  EXPECT_EQ(sweeps, pipeline.sweeps.capacity());
}

TEST(Pipeline, OneRecordedLaneIsExactlyTheProcessorsOutput) {
  const DaemonConfig config = trajroi::daemon::load_daemon_config(corridor_run() / "trajroid.yaml");
  Pipeline pipeline(config, /*exact=*/true, /*record=*/false);
  const std::vector<Item> items = run_items({});
  pipeline.add_input(std::make_unique<FakeInput>(items), 16, "test-replay", {});
  trajroi::pipeline::SweepProcessor processor(
      config, trajroi::daemon::load_trajectory(trajroi::daemon::TrajectorySource::from(config)));
  FakeOutlet outlet;
  EXPECT_EQ(trajroi::daemon::run_pipeline(pipeline, processor, outlet, {}, /*signals=*/false), 0);
  std::map<std::int64_t, std::size_t> published;
  for (const auto& bytes : outlet.messages(config.lcm.points)) {
    const auto m = decode<trajroi::points_t>(bytes);
    published[m.sweep_index] = static_cast<std::size_t>(m.num_points);
  }
  EXPECT_EQ(published, reference_kept(config));
  // The input thread decoded data packets ahead while the processing thread was busy (the
  // others that one decoded itself): the same sweeps either way.
  const auto statuses = outlet.messages(config.lcm.status);
  ASSERT_FALSE(statuses.empty());
  const auto data_packets = static_cast<std::int64_t>(
      std::count_if(items.begin(), items.end(), [](const Item& i) { return i.stream == inputs::Stream::kLidarData; }));
  const std::int64_t ahead = counter(decode<trajroi::status_t>(statuses.back()), "lidar.decoded_ahead");
  EXPECT_GT(ahead, 0);
  EXPECT_LE(ahead, data_packets);
}

// The evaluation (trajroi eval) runs the daemon's own pipeline: for the same run and the same
// configuration it keeps exactly the points trajroid publishes, sweep by sweep.
TEST(Pipeline, TheEvaluationKeepsExactlyWhatTheDaemonPublishes) {
  const trajroi::eval::ScenarioRun run(corridor_run());
  const DaemonConfig daemon_config = trajroi::daemon::load_daemon_config(corridor_run() / "trajroid.yaml");
  // The daemon: the recorded run through its threads, as fast as possible (exact).
  Pipeline pipeline(daemon_config, /*exact=*/true, /*record=*/false);
  pipeline.add_input(std::make_unique<inputs::RecordedInput>(corridor_run(), inputs::RecordedOptions{}),
                     daemon_config.buffers.lidar_packets, "test-replay", {});
  trajroi::pipeline::SweepProcessor processor(
      daemon_config, trajroi::daemon::load_trajectory(trajroi::daemon::TrajectorySource::from(daemon_config)));
  FakeOutlet outlet;
  ASSERT_EQ(trajroi::daemon::run_pipeline(pipeline, processor, outlet, {}, /*signals=*/false), 0);
  std::map<std::int64_t, trajroi::points_t> published;
  for (const auto& bytes : outlet.messages(daemon_config.lcm.points)) {
    auto m = decode<trajroi::points_t>(bytes);
    published.emplace(m.sweep_index, std::move(m));
  }

  // The evaluation: the configuration it builds for the daemon's shape and spacing.
  const auto eval_config = run.pipeline_config(daemon_config.roi.shape,
                                               static_cast<int>(std::lround(daemon_config.roi.spacing_ratio * 100.0)),
                                               daemon_config.pose_mode);
  struct Collect final : trajroi::eval::PipelineObserver {
    std::map<std::int64_t, trajroi::pipeline::Sweep> sweeps;
    void on_sweep(std::size_t, const trajroi::pipeline::Sweep& s, double) override {
      if (s.filtered) sweeps[static_cast<std::int64_t>(s.index)] = s;
    }
  } collect;
  trajroi::eval::run_pipelines(run, std::span<const DaemonConfig>(&eval_config, 1), collect);

  ASSERT_GT(published.size(), 100u);
  ASSERT_EQ(collect.sweeps.size(), published.size());
  std::size_t points = 0;
  for (const auto& [index, m] : published) {
    const auto it = collect.sweeps.find(index);
    ASSERT_NE(it, collect.sweeps.end()) << "sweep " << index;
    const trajroi::pipeline::Sweep& s = it->second;
    ASSERT_EQ(static_cast<std::size_t>(m.num_points), s.size()) << "sweep " << index;
    for (std::size_t i = 0; i < s.size(); ++i) {
      ASSERT_EQ(m.x[i], s.x[i]) << "sweep " << index << " point " << i;
      ASSERT_EQ(m.y[i], s.y[i]) << "sweep " << index << " point " << i;
      ASSERT_EQ(m.z[i], s.z[i]) << "sweep " << index << " point " << i;
    }
    EXPECT_EQ(s.point_index.size(), s.size());
    points += s.size();
  }
  EXPECT_GT(points, 1'000'000u);
}

// The run's first `seconds` at `rate` × real time in one paced lane, through the daemon's
// threads as live (a full ring drops), out through `outlet`.
void run_live(const DaemonConfig& config, int seconds, double rate, FakeOutlet& outlet) {
  std::vector<Item> items = run_items({});
  const std::int64_t end_ns = items.front().t_ns + std::int64_t{seconds} * 1'000'000'000;
  std::erase_if(items, [end_ns](const Item& i) { return i.t_ns > end_ns; });
  Pipeline pipeline(config, /*exact=*/false, /*record=*/false);
  pipeline.add_input(std::make_unique<FakeInput>(std::move(items), rate), config.buffers.lidar_packets, "test-run", {});
  SweepProcessor processor(config, trajroi::daemon::load_trajectory(trajroi::daemon::TrajectorySource::from(config)));
  trajroi::daemon::RunOptions options;
  options.replay = corridor_run();
  EXPECT_EQ(trajroi::daemon::run_pipeline(pipeline, processor, outlet, options, /*signals=*/false), 0);
}

// Live, a finished sweep goes out on the processing thread while the publisher thread is idle
// (no wake-up between them); realtime.publish_from_processing: false hands every sweep to the
// publisher thread. Either way the same messages, in the same order.
TEST(Pipeline, LiveSweepsGoOutOnTheProcessingThreadWhileThePublisherIsIdle) {
  const auto run = [](bool from_processing, FakeOutlet& outlet) {
    DaemonConfig config = trajroi::daemon::load_daemon_config(corridor_run() / "trajroid.yaml");
    config.realtime.publish_from_processing = from_processing;
    run_live(config, /*seconds=*/4, /*rate=*/4.0, outlet);
    const auto last = decode<trajroi::status_t>(outlet.messages(config.lcm.status).back());
    EXPECT_EQ(last.ring_drops, 0);
    return config.lcm.points;
  };
  FakeOutlet inline_outlet, handed_outlet;
  const std::string channel = run(true, inline_outlet);
  (void)run(false, handed_outlet);

  const std::vector<std::string> inline_senders = inline_outlet.senders(channel);
  const std::vector<std::string> handed_senders = handed_outlet.senders(channel);
  ASSERT_GT(inline_senders.size(), 30u);
  // The publisher thread is busy only around its once-a-second status and its 100 ms checks.
  const auto on = [](const std::vector<std::string>& senders, const std::string& thread) {
    return std::count(senders.begin(), senders.end(), thread);
  };
  EXPECT_GE(on(inline_senders, "trajroid-proc"), static_cast<std::ptrdiff_t>(inline_senders.size()) * 9 / 10);
  EXPECT_EQ(on(inline_senders, "trajroid-proc") + on(inline_senders, "trajroid-pub"),
            static_cast<std::ptrdiff_t>(inline_senders.size()));
  EXPECT_EQ(on(handed_senders, "trajroid-pub"), static_cast<std::ptrdiff_t>(handed_senders.size()));
  EXPECT_TRUE(inline_outlet.messages(channel) == handed_outlet.messages(channel))
      << inline_senders.size() << " and " << handed_senders.size() << " points messages";
}

// A sweep later than kLateSweep_ms from its last packet to LCM is counted (sweeps.late) and
// described: here an outlet that takes 6 ms to send each points message makes every published
// sweep late, at the sensors' pace (the live path; an as-fast replay's queue is not lateness).
TEST(Pipeline, LateSweepsAreCounted) {
  const DaemonConfig config = trajroi::daemon::load_daemon_config(corridor_run() / "trajroid.yaml");
  FakeOutlet outlet(config.lcm.points, std::chrono::milliseconds(6));
  // The daemon's log lines, kept for reading back.
  auto lines = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(256);
  auto& sinks = spdlog::default_logger()->sinks();
  sinks.push_back(lines);
  run_live(config, /*seconds=*/6, /*rate=*/2.0, outlet);
  sinks.pop_back();

  const auto published = outlet.messages(config.lcm.points);
  ASSERT_GT(published.size(), 20u);
  const auto last = decode<trajroi::status_t>(outlet.messages(config.lcm.status).back());
  EXPECT_EQ(last.ring_drops, 0);
  // Every whole sweep published is late; the last one may be the partial one flushed at the end.
  EXPECT_GE(counter(last, "sweeps.late"), static_cast<std::int64_t>(published.size()) - 1);
  EXPECT_LE(counter(last, "sweeps.late"), static_cast<std::int64_t>(published.size()));

  // A late sweep is described (once per warning interval): its latency split into five steps
  // that add up to it, the outlet's 6 ms in the sending. So is each minute's slowest sweep, on
  // the minute's line (here the final one).
  // The total after `first_label` (and after the sweep's index that follows it, when
  // `index_first`) and the figure after each step's label, in the line's order; empty when the
  // line has no `first_label`.
  const auto timing = [](const std::string& line, const std::string& first_label, bool index_first) {
    const std::vector<std::string> labels = {first_label,
                                             " ms from its last packet to LCM (waiting for the processing thread ",
                                             ", the closing packet and hand-over ",
                                             ", waiting for the publisher ",
                                             ", encoding ",
                                             ", sending "};
    std::vector<double> figures;
    std::size_t at = 0;
    for (const std::string& label : labels) {
      // Each label follows the previous figure (the first one's is the sweep index before it).
      const std::size_t found = line.find(label, at);
      if (found == std::string::npos) {
        EXPECT_TRUE(figures.empty()) << "no '" << label << "' in: " << line;
        return std::vector<double>{};
      }
      at = found + label.size();
      if (index_first && figures.empty()) {
        std::size_t digits = 0;
        (void)std::stoul(line.substr(at), &digits);
        at += digits;
        EXPECT_EQ(line[at], ' ') << line;
      }
      std::size_t used = 0;
      figures.push_back(std::stod(line.substr(at), &used));
      at += used;
    }
    EXPECT_EQ(line.compare(at, 4, " ms)"), 0) << line;
    const double steps = figures[1] + figures[2] + figures[3] + figures[4] + figures[5];
    EXPECT_NEAR(figures[0], steps, 0.031) << line;  // six figures, each rounded to 0.01
    EXPECT_GE(figures[5], 6.0) << line;
    return figures;
  };
  int described = 0;
  double latest_described_ms = 0.0;
  std::vector<double> slowest;
  for (const std::string& line : lines->last_formatted()) {
    if (line.find(" minute: ") != std::string::npos) {
      // The minute's maximum is its slowest sweep's total (each rounded to 0.01).
      slowest = timing(line, " | slowest: sweep ", true);
      ASSERT_FALSE(slowest.empty()) << line;
      const std::size_t max_at = line.find(" max ");
      ASSERT_NE(max_at, std::string::npos) << line;
      EXPECT_NEAR(std::stod(line.substr(max_at + 5)), slowest[0], 0.011) << line;
      continue;
    }
    if (line.find("late sweeps (over 5 ms) so far") == std::string::npos) continue;
    const std::vector<double> late = timing(line, " late: ", false);
    ASSERT_FALSE(late.empty()) << line;
    ++described;
    latest_described_ms = late[0];
  }
  EXPECT_GE(described, 1);
  ASSERT_FALSE(slowest.empty());
  EXPECT_GE(slowest[0], latest_described_ms - 0.011);  // none described was slower than the slowest
}

}  // namespace
