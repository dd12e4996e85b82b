#include "export_sources.hpp"

#include <fstream>
#include <stdexcept>

#include "trajroi/daemon/config.hpp"
#include "trajroi/daemon/trajectory_file.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/points_t.hpp"
#include "trajroi/transport/lcm_log.hpp"

namespace trajroi::cli {

namespace fs = std::filesystem;

SourceSummary read_lcm_log(const fs::path& log, const std::string& channel, const SweepHandler& on_sweep,
                           const Progress& progress) {
  std::ifstream in(log, std::ios::binary);
  if (!in) throw std::runtime_error(log.string() + ": cannot open");
  const auto total = static_cast<double>(fs::file_size(log));
  transport::LcmLogReader reader(in);
  transport::LcmLogEvent event;
  SourceSummary summary;
  std::uint64_t other_channels = 0, not_points = 0;
  transport::LcmLogReader::Next next;
  while ((next = reader.next(event)) == transport::LcmLogReader::Next::kEvent) {
    if (event.channel != channel) {
      ++other_channels;
      continue;
    }
    trajroi::points_t m;
    if (m.decode(event.data.data(), 0, static_cast<int>(event.data.size())) != static_cast<int>(event.data.size())) {
      ++not_points;  // another type on the channel, or a damaged message
      continue;
    }
    on_sweep({cloud_io::from_points(m), m.sweep_index, m.sweep_start_ns});
    ++summary.sweeps;
    progress(static_cast<double>(reader.event_offset()) / total, summary.sweeps);
  }
  summary.skipped = std::to_string(other_channels) + " events of other channels, " + std::to_string(not_points) +
                    " messages on " + channel + " that are not points_t, " + std::to_string(reader.skipped_bytes()) +
                    " bytes between events";
  if (next == transport::LcmLogReader::Next::kCut) {
    summary.cut = log.string() + ": cut short: its last event, from byte " + std::to_string(reader.event_offset()) +
                  ", is incomplete";
  }
  if (summary.sweeps == 0 && summary.cut.empty())
    throw std::runtime_error(log.string() + ": no points_t on " + channel + " (--channel)");
  return summary;
}

namespace {

// The sweeps as trajroid publishes them, as clouds.
class CloudSink final : public pipeline::SweepSink {
 public:
  explicit CloudSink(const SweepHandler& on_sweep) : on_sweep_(on_sweep) {}
  void on_sweep(pipeline::Sweep& s) override {
    if (!s.filtered) {
      ++withheld_;
      return;
    }
    cloud_.clear();
    cloud_.reserve(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      cloud_.push(s.x[i], s.y[i], s.z[i], static_cast<float>(s.intensity[i]), s.ring[i],
                  static_cast<float>(static_cast<double>(s.time_offset_ns[i]) * 1e-9), s.return_type[i]);
    }
    cloud_.start_utc_ns = s.start_utc_ns;
    cloud_.return_mode = s.return_mode;
    cloud_.comment = "trajroi: sweep " + std::to_string(s.index) + ", trajectory " + std::to_string(s.trajectory_id) +
                     ", global frame (x east, y north, z up, m)";
    on_sweep_({cloud_, static_cast<std::int64_t>(s.index), s.start_ns});
    ++published_;
  }
  std::uint64_t published_ = 0, withheld_ = 0;

 private:
  const SweepHandler& on_sweep_;
  cloud_io::Cloud cloud_;
};

}  // namespace

SourceSummary replay_run_folder(const fs::path& dir, const fs::path& config_path, const SweepHandler& on_sweep,
                                const Progress& progress) {
  const fs::path file = config_path.empty() ? dir / "trajroid.yaml" : config_path;
  if (!fs::exists(file))
    throw std::runtime_error(file.string() + ": no trajroid configuration for the run folder (--config)");
  const daemon::DaemonConfig config = daemon::load_daemon_config(file);
  pipeline::SweepProcessor processor(config, daemon::load_trajectory(daemon::TrajectorySource::from(config)));
  inputs::LidarPorts ports;
  for (const daemon::DaemonConfig::Lidar& l : config.all_lidars())
    ports.emplace_back(l.data_port, l.position_port);  // several LiDARs record theirs
  inputs::RunMerger merger(
      dir,
      inputs::RunStreams{
          true, config.pose_source != daemon::PoseSource::kLcm && config.pose_source != daemon::PoseSource::kFixed,
          config.pose_source == daemon::PoseSource::kGnssImu},
      0, ports);
  const auto total = static_cast<double>(fs::file_size(dir / inputs::kLidarFile));
  CloudSink sink(on_sweep);
  inputs::InputItem item;
  std::uint64_t lidar_bytes = 0;
  while (merger.next(item)) {
    processor.process(item, sink);
    if (inputs::is_lidar(item.stream)) {
      lidar_bytes += item.bytes.size() + 58;  // each datagram's pcap record and headers: about
      progress(std::min(1.0, static_cast<double>(lidar_bytes) / total), sink.published_);
    }
  }
  processor.flush(sink);
  SourceSummary summary;
  summary.sweeps = sink.published_;
  summary.skipped = std::to_string(sink.withheld_) + " sweeps withheld without a valid pose (as trajroid would)";
  return summary;
}

}  // namespace trajroi::cli
