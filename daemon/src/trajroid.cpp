// The wiring: sources, rings and threads, signals, the service manager's notifications and
// watchdog, the summary.
#include "trajroid.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <algorithm>
#include <future>
#include <thread>
#include <vector>

#include "chrony_shm.hpp"
#include "corrections_link.hpp"
#include "lcm_pose_input.hpp"
#include "log.hpp"
#include "outlet.hpp"
#include "pipeline.hpp"
#include "publisher.hpp"
#include "realtime.hpp"
#include "reload.hpp"
#include "service_notify.hpp"
#include "threads.hpp"
#include "trajroi/configure/receiver_config.hpp"
#include "trajroi/inputs/live_input.hpp"
#include "trajroi/inputs/recorded_input.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/roi/cpu.hpp"

namespace trajroi::daemon {

namespace {

// An as-fast-as-possible replay waits on a full ring instead of dropping, so its ring only
// covers the reader's pauses: as many packets as it may decode ahead (≈ 0.5 ms of processing)
// at most, not the live depth (seconds of packets, 5 MB written at start-up).
constexpr std::size_t kExactReplayRing = kDecodeAhead;

// gnss.configure / imu.configure: the receiver's output set each time its device opens; the
// outcome (and each refused step) is said with the open.
inputs::SerialInput::OnOpen receiver_configuration(const DaemonConfig& config, inputs::Stream stream) {
  return [&config, stream](serial::SerialPortSource& port) {
    configure::Result r;
    if (stream == inputs::Stream::kGnss) {
      configure::UbloxSettings s;
      s.rate_hz = config.gnss.rate_hz;
      s.port = configure::guess_ublox_port(config.gnss.device);
      s.relposned = config.pose_source == PoseSource::kGnss;
      s.rtcm3_input = !config.gnss_corrections.url.empty();
      r = configure::configure_ublox(port, s);
    } else {
      configure::Vn100Settings s;
      s.rate_hz = config.imu.rate_hz;
      r = configure::configure_vn100(port, s);
    }
    std::string text = r.summary;
    for (const configure::Step& step : r.steps) {
      if (!step.ok) text += "; " + step.what + ": " + step.answer;
    }
    return inputs::Notice{r.ok ? inputs::Notice::Level::kInfo : inputs::Notice::Level::kWarning, text};
  };
}

// The live sensors, or the recorded run: the only difference between live and replay.
// `own_source`: the source of the daemon's own LCM datagrams, which an input over LCM leaves out.
void add_inputs(Pipeline& pipeline, const DaemonConfig& config, const RunOptions& options,
                const std::optional<sockaddr_in>& own_source) {
  if (options.replay) {
    if (!config.gnss_corrections.url.empty())
      log::info("gnss.corrections.url: not used in a replay (no receiver to write into)");
    if (config.time.chrony_shm) log::info("time.chrony_shm: not used in a replay (the recording's time is not now)");
    inputs::RecordedOptions recorded;
    recorded.rate = options.rate;
    recorded.loop = options.loop;
    for (const DaemonConfig::Lidar& l : config.all_lidars())
      recorded.lidar_ports.emplace_back(l.data_port, l.position_port);
    const std::size_t ring =
        options.rate == 0.0 ? std::min(config.buffers.lidar_packets, kExactReplayRing) : config.buffers.lidar_packets;
    pipeline.add_input(std::make_unique<inputs::RecordedInput>(*options.replay, recorded), ring, "trajroid-replay",
                       config.realtime.lidar);
    return;
  }
  // One pair of sockets per pair of ports: sensors sharing ports share the sockets (their
  // packets told apart by sender in the processor), each only its sender when alone.
  const std::vector<DaemonConfig::Lidar> lidars = config.all_lidars();
  for (std::size_t i = 0; i < lidars.size(); ++i) {
    const DaemonConfig::Lidar& l = lidars[i];
    bool opened = false;
    std::size_t sharing = 0;
    for (std::size_t j = 0; j < lidars.size(); ++j) {
      if (lidars[j].data_port != l.data_port) continue;
      opened = opened || j < i;
      ++sharing;
    }
    if (opened) continue;
    vlp16::UdpOptions udp;
    udp.bind_address = l.bind_address;
    udp.data_port = l.data_port;
    udp.position_port = l.position_port;
    udp.receive_buffer_bytes = l.receive_buffer_bytes;
    udp.sensor_address = sharing == 1 ? l.sensor_address : std::string();
    udp.share_ports = l.share_ports;
    auto lidar = std::make_unique<inputs::UdpInput>(udp);
    if (sharing > 1) {
      std::string who;
      for (const DaemonConfig::Lidar& other : lidars) {
        if (other.data_port == l.data_port) who += (who.empty() ? "" : ", ") + other.name + " " + other.sensor_address;
      }
      log::info(
          "lidars on UDP {}:{}/{} told apart by sender: {}; other senders' datagrams dropped "
          "(lidar.rejected_source)",
          l.bind_address, l.data_port, l.position_port, who);
    }
    const std::string thread = lidars.size() == 1 ? "trajroid-lidar" : ("trajroid-l-" + l.name).substr(0, 15);
    pipeline.add_input(std::move(lidar), config.buffers.lidar_packets, thread, config.realtime.lidar);
  }
  const auto add_serial = [&](const DaemonConfig::Serial& s, const char* name, inputs::Stream stream,
                              const ThreadConfig& thread) {
    if (s.device.empty()) {
      log::warn("{}: no device configured: that stream is silent", name);
      return;
    }
    serial::SerialPortOptions o;
    o.device = s.device;
    o.baud = s.baud;
    // A receiver that comes back (cable, USB re-enumeration) is read again within 0.5 s.
    o.max_backoff = std::chrono::milliseconds(500);
    auto input = std::make_unique<inputs::SerialInput>(name, stream, o);
    if (s.configure) input->on_open(receiver_configuration(config, stream));
    if (stream == inputs::Stream::kGnss && !config.gnss_corrections.url.empty()) {
      pipeline.corrections =
          std::make_unique<CorrectionsLink>(config, options.lcm_url.empty() ? config.lcm.url : options.lcm_url);
      pipeline.corrections->open();  // a UDP port or LCM that cannot be opened: named, exit 1
      CorrectionsLink* link = pipeline.corrections.get();
      input->before_read([link](serial::SerialPortSource& port) { link->write_waiting(port); });
    }
    pipeline.add_input(std::move(input), config.buffers.serial_chunks, std::string("trajroid-") + name, thread,
                       Pipeline::Lidar::kNone);
  };
  // What the pose source reads (a device configured for an unused stream is left closed).
  if (config.pose_source == PoseSource::kGnssImu || config.pose_source == PoseSource::kGnss) {
    add_serial(config.gnss, "gnss", inputs::Stream::kGnss, config.realtime.gnss);
  }
  if (config.time.chrony_shm) {
    if (config.pose_source == PoseSource::kGnssImu || config.pose_source == PoseSource::kGnss) {
      pipeline.chrony = std::make_unique<ChronyShm>(*config.time.chrony_shm);
    } else {
      log::warn("time.chrony_shm is set but trajroid reads no GNSS port (pose.source {}): no time for chrony",
                to_string(config.pose_source));
    }
  }
  if (!config.gnss_corrections.url.empty() && !pipeline.corrections) {
    log::warn(
        "gnss.corrections.url is set but trajroid reads no GNSS port (pose.source {}, gnss.device \"{}\"): "
        "no corrections are taken",
        to_string(config.pose_source), config.gnss.device);
  }
  if (config.pose_source == PoseSource::kGnssImu)
    add_serial(config.imu, "imu", inputs::Stream::kImu, config.realtime.imu);
  if (config.pose_source == PoseSource::kLcm) {
    pipeline.add_input(std::make_unique<LcmPoseInput>(options.lcm_url.empty() ? config.lcm.url : options.lcm_url,
                                                      config.lcm.pose_input, own_source),
                       config.buffers.serial_chunks, "trajroid-posein", config.realtime.gnss, Pipeline::Lidar::kNone);
  }
}

// The ROI scan this machine runs fastest, with what was measured and where.
void log_scan_calibration(const roi::ScanCalibration& c, RoiShape shape) {
  log::info("roi scan for {}: {} on {}", shape == RoiShape::kCircular ? "circles" : "rectangles", roi::describe(c),
            roi::describe_machine());
  log::info("vlp16 decoder: {}", vlp16::describe(vlp16::decoder_calibration()));
}

// Signals go to the main thread only, through a signalfd (-1 when not handled).
int block_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  return signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC);
}

void log_summary(const Pipeline& pipeline, const Publisher& publisher, std::int64_t start_ns, bool replay) {
  const StatusSnapshot& s = publisher.last_status();
  const LatencyHistogram& latency = publisher.latency();
  const double wall_s = static_cast<double>(host::monotonic_ns() - start_ns) * 1e-9;
  const auto& p = s.processor;
  log::info(
      "summary: {:.3f} s | sweeps {} published {} withheld (no pose) {} | points in {} kept {} ({:.1f} %) | "
      "latency p50 {:.3f} ms p99 {:.3f} ms over {} sweeps | ring drops {} | lost packets {} | decode errors {}{}",
      wall_s, p.sweeps, p.sweeps_filtered, p.sweeps_without_pose, p.points_in, p.points_kept,
      p.points_in > 0 ? 100.0 * static_cast<double>(p.points_kept) / static_cast<double>(p.points_in) : 0.0,
      latency.quantile(0.5), latency.quantile(0.99), latency.count(), s.ring_drops(), s.lost_packets, s.decode_errors,
      // Several LiDARs merged: the sweeps above are the sensors'; these are what went out.
      pipeline.config.merges_sweeps() ? fmt::format(" | merged sweeps published {} ({} without a sensor waited for)",
                                                    s[Counter::kMergePublished], s[Counter::kMergeIncomplete])
                                      : std::string());
  log::info("cpu: sources {:.3f} s ({}; {} LiDAR packets decoded ahead), processing {:.3f} s, publishing {:.3f} s",
            static_cast<double>(pipeline.cpu_sources_ns.load()) * 1e-9, replay ? "replay reader" : "receive threads",
            s[Counter::kLidarDecodedAhead], static_cast<double>(pipeline.cpu_processing_ns.load()) * 1e-9,
            static_cast<double>(pipeline.cpu_publishing_ns.load()) * 1e-9);
}

}  // namespace

int run_pipeline(Pipeline& pipeline, pipeline::SweepProcessor& processor, Outlet& outlet, const RunOptions& options,
                 bool signals) {
  const std::int64_t start_ns = host::monotonic_ns();
  const int sfd = signals ? block_signals() : -1;
  pipeline.processor = &processor;  // the input threads route and decode ahead with its lanes' decoders
  Reloader reloader(TrajectorySource::from(pipeline.config), pipeline.publish_wake);
  Publisher publisher(pipeline, outlet, &reloader, options.replay.has_value(), processor.active_trajectory());
  ProcessingOptions processing;
  processing.stall_after_s = options.stall_processing_after_s;
  processing.live = !options.replay.has_value();

  // Said from this thread before any other starts (which also sets up the logger once).
  for (const auto& lane : pipeline.inputs)
    log::info("input: {} ({})", lane->source->describe(), lane->thread_name);

  std::vector<std::thread> threads;
  threads.emplace_back([&] { processing_loop(pipeline, processor, processing); });
  threads.emplace_back([&] { publisher.run(); });
  if (pipeline.record) threads.emplace_back([&] { recorder_loop(pipeline, *options.record); });
  if (pipeline.corrections) threads.emplace_back([&] { pipeline.corrections->run(pipeline.stop); });
  for (const auto& lane : pipeline.inputs)
    threads.emplace_back([&pipeline, &lane] { input_loop(pipeline, *lane); });
  (void)notify_service("READY=1\nSTATUS=running");

  if (!service_notifier().problem().empty())
    log::warn("{}: the service manager is not told", service_notifier().problem());
  const std::uint64_t watchdog_interval_usec = watchdog_usec();
  const bool watchdog = watchdog_interval_usec > 0;
  const int wait_ms = watchdog ? static_cast<int>(std::max<std::uint64_t>(watchdog_interval_usec / 4000, 10)) : 1000;
  std::uint64_t last_processing = 0, last_publishing = 0;
  for (;;) {
    pollfd fds[2] = {{sfd, POLLIN, 0}, {pipeline.main_wake.fd(), POLLIN, 0}};
    (void)poll(fds, 2, wait_ms);
    if ((fds[1].revents & POLLIN) != 0) pipeline.main_wake.drain();
    if ((fds[0].revents & POLLIN) != 0) {
      signalfd_siginfo info{};
      while (read(sfd, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
        if (info.ssi_signo == SIGHUP) {
          log::info("SIGHUP: reloading the trajectory");
          reloader.request();
        } else {
          log::info("{}: stopping", info.ssi_signo == SIGTERM ? "SIGTERM" : "SIGINT");
          (void)notify_service("STOPPING=1");
          pipeline.stop.store(true);
        }
      }
    }
    if (pipeline.publishing_done.load(std::memory_order_acquire)) break;
    if (watchdog) {
      // Fed only while both the processing and the publishing loops turn.
      const std::uint64_t a = pipeline.processing_beat.load(std::memory_order_relaxed);
      const std::uint64_t b = pipeline.publishing_beat.load(std::memory_order_relaxed);
      if (a != last_processing && b != last_publishing) (void)notify_service("WATCHDOG=1");
      last_processing = a;
      last_publishing = b;
    }
  }
  pipeline.stop.store(true);
  for (std::thread& t : threads)
    t.join();
  if (sfd >= 0) close(sfd);
  log_summary(pipeline, publisher, start_ns, options.replay.has_value());
  return 0;
}

int run_daemon(const DaemonConfig& config, std::unique_ptr<pipeline::ActiveTrajectory> trajectory,
               const RunOptions& options) {
  std::unique_ptr<pipeline::SweepProcessor> processor;
  try {
    log::info("trajectory: {} ({} waypoints, {:.1f} m)", config.trajectory_file.string(),
              trajectory->trajectory.waypoints().size(), trajectory->trajectory.length_m());
    processor = std::make_unique<pipeline::SweepProcessor>(config, std::move(trajectory));
  } catch (const std::exception& e) {
    // The lidar calibration: part of the configuration.
    log::critical("{}: {}", config.file.string(), e.what());
    return kExitConfig;
  }
  // The scans and then the decoder's builds are timed on another thread while the rings are
  // allocated and the sources opened (start-up is part of a replay's time: on this one, they
  // kept it waiting 3–5 ms); a path forced by TRAJROI_SIMD is taken at once.
  std::future<roi::ScanCalibration> scan = std::async(std::launch::async, [&processor] {
    const roi::ScanCalibration calibration = processor->calibrate_scan();
    (void)vlp16::decoder_calibration();
    return calibration;
  });
  const bool exact = options.replay.has_value() && options.rate == 0.0;
  if (!exact) processor->make_resident();  // see Pipeline::exact
  Pipeline pipeline(config, exact, options.record.has_value());
  // The outlet first: an input over LCM leaves out the outlet's own datagrams.
  const std::string url = options.lcm_url.empty() ? config.lcm.url : options.lcm_url;
  std::unique_ptr<Outlet> outlet;
  try {
    outlet = make_outlet(url);
  } catch (const std::exception& e) {
    log::critical("{}", e.what());
    return 1;
  }
  const auto* udpm_outlet = dynamic_cast<const UdpmOutlet*>(outlet.get());
  try {
    add_inputs(pipeline, config, options, udpm_outlet != nullptr ? udpm_outlet->own_source() : std::nullopt);
  } catch (const std::exception& e) {
    log::critical("cannot open the sources: {}", e.what());
    return 1;
  }
  if (options.record) {
    std::error_code ec;
    std::filesystem::create_directories(*options.record, ec);
    if (ec) {
      log::critical("--record {}: {}", options.record->string(), ec.message());
      return 1;
    }
    pipeline.record_dir = options.record->string();
    log::info("recording every raw input into {} ({}, {}, {}{}; replay it with trajroid --replay {})",
              pipeline.record_dir, inputs::kLidarFile, inputs::kGnssFile, inputs::kImuFile,
              config.pose_source == PoseSource::kLcm ? std::string(", ") + inputs::kPoseFile : std::string(),
              pipeline.record_dir);
  }
  if (config.realtime.lock_memory) {
    if (const std::string w = lock_memory(); !w.empty()) log::warn("{}", w);
  }
  log_scan_calibration(scan.get(), config.roi.shape);
  log::info("trajroid running: {} → LCM {} ({}, {}, {}, {}; trajectory input on {})",
            options.replay ? "replay of " + options.replay->string() : std::string("live sensors"), url,
            config.lcm.points, config.lcm.pose, config.lcm.roi, config.lcm.status, config.lcm.trajectory);
  return run_pipeline(pipeline, *processor, *outlet, options, true);
}

}  // namespace trajroi::daemon
