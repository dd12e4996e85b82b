#pragma once

// The one merger: a run folder's recordings — lidar.pcap (data and position packets),
// gnss.trjb and imu.trjb, and pose.trjb when there is one — read as one stream of items in recorded receive-time order
// (ties: GNSS, then IMU, then LiDAR, so a pose sample recorded with a packet is known before it). The same order on
// every run: what makes a replay exact.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "trajroi/inputs/input_source.hpp"
#include "trajroi/serial/byte_log.hpp"

namespace trajroi::vlp16 {
class PcapSource;
}

namespace trajroi::inputs {

inline constexpr const char* kLidarFile = "lidar.pcap";
inline constexpr const char* kGnssFile = "gnss.trjb";
inline constexpr const char* kImuFile = "imu.trjb";
inline constexpr const char* kPoseFile = "pose.trjb";  // pose.source lcm: the localization's messages

struct RunStreams {
  bool lidar = true, gnss = true, imu = true;
};

// The pcap's LiDAR ports beside the standard 2368/8308: data and position pairs (several LiDARs
// record theirs).
using LidarPorts = std::vector<std::pair<std::uint16_t, std::uint16_t>>;

// Captures named one by one instead of a run folder (trajroi feed): a pcap, and serial files
// (recordings, or raw logs timed by their options: serial::RawTiming). Empty paths are silent
// streams.
struct RunFiles {
  std::filesystem::path lidar, gnss, imu;
  serial::ReplayOptions gnss_options, imu_options;
  // The pcap's datagrams keep their recorded spacing, the first one at this time (the serial
  // files' raw times start at their options' start_time_ns); unset: as recorded.
  std::optional<std::int64_t> lidar_start_ns;
};

class RunMerger {
 public:
  // Opens the folder's recordings (the streams asked for). A missing gnss.trjb or imu.trjb
  // leaves that stream silent (missing() names it); a missing or unreadable lidar.pcap
  // throws std::runtime_error naming it. `shift_ns` is added to every recorded time.
  RunMerger(const std::filesystem::path& dir, RunStreams streams = {}, std::int64_t shift_ns = 0,
            const LidarPorts& lidar_ports = {});
  // The same merge over captures named one by one. Throws std::runtime_error naming a file that
  // cannot be read (or, raw, timed).
  explicit RunMerger(const RunFiles& files);
  ~RunMerger();
  RunMerger(const RunMerger&) = delete;
  RunMerger& operator=(const RunMerger&) = delete;

  // The next item in receive-time order; false at the end of every recording. `item.bytes`
  // stays valid until the next call.
  bool next(InputItem& item);
  // The receive time of the item next() returns next, or false at the end.
  [[nodiscard]] bool peek_time(std::int64_t& receive_ns) noexcept;

  [[nodiscard]] const std::vector<std::string>& missing() const noexcept { return missing_; }
  // A recording cut or unreadable mid-way ends that stream; this says why (empty: none).
  [[nodiscard]] const std::string& error() const noexcept { return error_; }
  [[nodiscard]] std::uint64_t oversize() const noexcept { return oversize_; }
  // First and last recorded times handed out so far (after the shift).
  [[nodiscard]] std::int64_t first_ns() const noexcept { return first_ns_; }
  [[nodiscard]] std::int64_t last_ns() const noexcept { return last_ns_; }

 private:
  struct Pending {
    bool have = false;
    std::int64_t t = 0;
    Stream stream = Stream::kLidarData;
    std::uint64_t sender = 0;  // a datagram's (0: serial bytes)
    std::uint16_t port = 0;    // its destination port
    std::vector<std::uint8_t> bytes;
  };
  void fill_lidar();
  std::vector<std::uint16_t> position_ports_;
  void fill_serial(serial::ReplaySource* source, Pending& p, Stream stream);
  [[nodiscard]] Pending* earliest() noexcept;

  std::unique_ptr<vlp16::PcapSource> pcap_;
  std::unique_ptr<serial::ReplaySource> gnss_, imu_, pose_;
  std::int64_t shift_ns_ = 0;
  std::optional<std::int64_t> lidar_start_ns_;  // RunFiles::lidar_start_ns
  std::optional<std::int64_t> lidar_shift_ns_;  // set at the first datagram
  Pending lidar_, gnss_next_, imu_next_, pose_next_;
  std::vector<std::uint8_t> out_;  // the item handed out
  std::vector<std::string> missing_;
  std::string error_;
  std::uint64_t oversize_ = 0;
  std::int64_t first_ns_ = INT64_MAX, last_ns_ = INT64_MIN;
};

}  // namespace trajroi::inputs
