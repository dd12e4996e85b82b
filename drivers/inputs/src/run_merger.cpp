#include "trajroi/inputs/run_merger.hpp"

#include <algorithm>
#include <stdexcept>

#include "trajroi/serial/byte_log.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::inputs {

namespace fs = std::filesystem;

RunMerger::RunMerger(const fs::path& dir, RunStreams streams, std::int64_t shift_ns, const LidarPorts& lidar_ports)
    : shift_ns_(shift_ns) {
  position_ports_ = {vlp16::kPositionPort};
  if (streams.lidar) {
    vlp16::PcapOptions options;
    options.ports = {vlp16::kDataPort, vlp16::kPositionPort};
    for (const auto& [data, position] : lidar_ports) {
      options.ports.push_back(data);
      options.ports.push_back(position);
      position_ports_.push_back(position);
    }
    pcap_ = std::make_unique<vlp16::PcapSource>(dir / kLidarFile, options);
  }
  const auto open_serial = [&](bool wanted, const char* name) -> std::unique_ptr<serial::ReplaySource> {
    if (!wanted) return nullptr;
    if (!fs::exists(dir / name)) {
      missing_.push_back((dir / name).string());
      return nullptr;
    }
    return std::make_unique<serial::ReplaySource>((dir / name).string());
  };
  gnss_ = open_serial(streams.gnss, kGnssFile);
  imu_ = open_serial(streams.imu, kImuFile);
  // Only runs recorded with pose.source lcm have one: not missing when absent.
  if (fs::exists(dir / kPoseFile)) pose_ = std::make_unique<serial::ReplaySource>((dir / kPoseFile).string());
  fill_lidar();
  fill_serial(gnss_.get(), gnss_next_, Stream::kGnss);
  fill_serial(imu_.get(), imu_next_, Stream::kImu);
  fill_serial(pose_.get(), pose_next_, Stream::kPose);
}

RunMerger::RunMerger(const RunFiles& files)
    : position_ports_{vlp16::kPositionPort}, lidar_start_ns_(files.lidar_start_ns) {
  if (!files.lidar.empty()) {
    vlp16::PcapOptions options;
    options.ports = {vlp16::kDataPort, vlp16::kPositionPort};
    pcap_ = std::make_unique<vlp16::PcapSource>(files.lidar, options);
  }
  const auto open_serial = [](const fs::path& file, const serial::ReplayOptions& options) {
    return file.empty() ? nullptr : std::make_unique<serial::ReplaySource>(file.string(), options);
  };
  gnss_ = open_serial(files.gnss, files.gnss_options);
  imu_ = open_serial(files.imu, files.imu_options);
  fill_lidar();
  fill_serial(gnss_.get(), gnss_next_, Stream::kGnss);
  fill_serial(imu_.get(), imu_next_, Stream::kImu);
}

RunMerger::~RunMerger() = default;

void RunMerger::fill_lidar() {
  lidar_.have = false;
  if (!pcap_) return;
  vlp16::Datagram d;
  for (;;) {
    const auto r = pcap_->next(d);
    if (r != vlp16::PacketSource::Next::kDatagram) {
      if (r == vlp16::PacketSource::Next::kError) error_ = pcap_->error();
      return;
    }
    if (d.payload.size() > kMaxDatagramBytes) {
      ++oversize_;
      continue;
    }
    lidar_.have = true;
    if (lidar_start_ns_ && !lidar_shift_ns_) lidar_shift_ns_ = *lidar_start_ns_ - d.receive_time_ns;
    lidar_.t = d.receive_time_ns + lidar_shift_ns_.value_or(0) + shift_ns_;
    const bool position =
        std::find(position_ports_.begin(), position_ports_.end(), d.destination_port) != position_ports_.end();
    lidar_.stream = position ? Stream::kLidarPosition : Stream::kLidarData;
    lidar_.sender = d.sender;
    lidar_.port = d.destination_port;
    lidar_.bytes.assign(d.payload.begin(), d.payload.end());
    return;
  }
}

void RunMerger::fill_serial(serial::ReplaySource* source, Pending& p, Stream stream) {
  serial::Chunk chunk;
  p.have = source != nullptr && source->read(chunk, std::chrono::milliseconds(0)) == serial::ReadStatus::kData;
  if (p.have) {
    p.t = chunk.receive_time_ns + shift_ns_;
    p.stream = stream;
    p.bytes.assign(chunk.bytes.begin(), chunk.bytes.end());
  }
}

RunMerger::Pending* RunMerger::earliest() noexcept {
  Pending* p = nullptr;
  for (Pending* c : {&gnss_next_, &imu_next_, &pose_next_, &lidar_}) {
    if (c->have && (p == nullptr || c->t < p->t)) p = c;
  }
  return p;
}

bool RunMerger::peek_time(std::int64_t& receive_ns) noexcept {
  const Pending* p = earliest();
  if (p == nullptr) return false;
  receive_ns = p->t;
  return true;
}

bool RunMerger::next(InputItem& item) {
  Pending* p = earliest();
  if (p == nullptr) return false;
  out_.swap(p->bytes);
  item.stream = p->stream;
  item.sender = p->sender;
  item.port = p->port;
  item.receive_ns = p->t;
  item.bytes = out_;
  first_ns_ = std::min(first_ns_, p->t);
  last_ns_ = std::max(last_ns_, p->t);
  if (p == &lidar_) {
    fill_lidar();
  } else if (p == &gnss_next_) {
    fill_serial(gnss_.get(), gnss_next_, Stream::kGnss);
  } else if (p == &pose_next_) {
    fill_serial(pose_.get(), pose_next_, Stream::kPose);
  } else {
    fill_serial(imu_.get(), imu_next_, Stream::kImu);
  }
  return true;
}

}  // namespace trajroi::inputs
