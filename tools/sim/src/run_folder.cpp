#include "trajroi/sim/run_folder.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>
#include <random>
#include <stdexcept>

#include "trajroi/framing/little_endian.hpp"
#include "trajroi/serial/byte_log.hpp"
#include "trajroi/vlp16/packet_source.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::sim {
namespace fs = std::filesystem;
namespace {

constexpr char kPosesMagic[8] = {'T', 'R', 'J', 'P', 'O', 'S', 'E', 'S'};
constexpr char kLabelsMagic[8] = {'T', 'R', 'J', 'L', 'A', 'B', 'E', 'L'};
constexpr std::uint32_t kTruthVersion = 1;
constexpr std::uint32_t kPoseRecordBytes = 32;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

// A file written through stdio with errors turned into exceptions naming it.
class BinaryFile {
 public:
  explicit BinaryFile(fs::path path) : path_(std::move(path)), file_(std::fopen(path_.c_str(), "wb")) {
    if (file_ == nullptr) throw std::runtime_error(path_.string() + ": cannot create: " + std::strerror(errno));
  }
  ~BinaryFile() {
    if (file_ != nullptr) std::fclose(file_);
  }
  BinaryFile(const BinaryFile&) = delete;
  BinaryFile& operator=(const BinaryFile&) = delete;
  void write(const void* data, std::size_t bytes) {
    if (bytes != 0 && std::fwrite(data, 1, bytes, file_) != bytes) fail("write");
  }
  void seek_start() {
    if (std::fseek(file_, 0, SEEK_SET) != 0) fail("seek");
  }
  void close() {
    const int rc = std::fclose(file_);
    file_ = nullptr;
    if (rc != 0) fail("close");
  }

 private:
  [[noreturn]] void fail(const char* what) {
    throw std::runtime_error(path_.string() + ": cannot " + what + ": " + std::strerror(errno));
  }
  fs::path path_;
  std::FILE* file_;
};

void append_f64(std::vector<std::uint8_t>& out, double v) {
  framing::put_le_u64(out, std::bit_cast<std::uint64_t>(v));
}

std::vector<std::uint8_t> read_all(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

class FolderSink final : public SimulationSink {
 public:
  explicit FolderSink(const fs::path& dir)
      : pcap_(dir / kLidarFile),
        gnss_((dir / kGnssFile).string()),
        imu_((dir / kImuFile).string()),
        poses_(dir / kTruthPosesFile),
        labels_(dir / kTruthLabelsFile) {
    std::vector<std::uint8_t> header(std::begin(kPosesMagic), std::end(kPosesMagic));
    framing::put_le_u32(header, kTruthVersion);
    framing::put_le_u32(header, kPoseRecordBytes);
    poses_.write(header.data(), header.size());
    write_labels_header();
  }

  void lidar_datagram(std::int64_t receive_ns, std::uint16_t port, std::span<const std::uint8_t> payload) override {
    pcap_.write(receive_ns, port, payload);
  }
  void gnss_chunk(std::int64_t receive_ns, std::span<const std::uint8_t> bytes) override {
    gnss_.write(serial::Chunk{bytes, receive_ns});
  }
  void imu_chunk(std::int64_t receive_ns, std::span<const std::uint8_t> bytes) override {
    imu_.write(serial::Chunk{bytes, receive_ns});
  }
  void firing_pose(const TruePose& pose) override {
    record_.clear();
    framing::put_le_u64(record_, static_cast<std::uint64_t>(pose.t_ns));
    append_f64(record_, pose.x_m);
    append_f64(record_, pose.y_m);
    append_f64(record_, pose.yaw_rad);
    poses_.write(record_.data(), record_.size());
  }
  void point_labels(std::span<const std::uint8_t> labels) override {
    for (const std::uint8_t label : labels) {
      if (label != 0) bits_ |= static_cast<std::uint8_t>(1U << (label_count_ % 8));
      if (++label_count_ % 8 == 0) {
        labels_.write(&bits_, 1);
        bits_ = 0;
      }
    }
  }

  void close() {
    pcap_.close();
    gnss_.flush();
    imu_.flush();
    poses_.close();
    if (label_count_ % 8 != 0) labels_.write(&bits_, 1);
    labels_.seek_start();
    write_labels_header();
    labels_.close();
  }

 private:
  void write_labels_header() {
    std::vector<std::uint8_t> header(std::begin(kLabelsMagic), std::end(kLabelsMagic));
    framing::put_le_u32(header, kTruthVersion);
    framing::put_le_u32(header, 0);
    framing::put_le_u64(header, label_count_);
    labels_.write(header.data(), header.size());
  }

  vlp16::PcapWriter pcap_;
  serial::RecordingWriter gnss_;
  serial::RecordingWriter imu_;
  BinaryFile poses_;
  BinaryFile labels_;
  std::vector<std::uint8_t> record_;
  std::uint64_t label_count_ = 0;
  std::uint8_t bits_ = 0;
};

void write_text(const fs::path& path, const std::string& text) {
  BinaryFile file(path);
  file.write(text.data(), text.size());
  file.close();
}

std::string daemon_config(const Scenario& s) {
  const Mounting& m = s.robot.lidar;
  const auto& e = s.evaluation;
  char text[4096];
  std::snprintf(text, sizeof text,
                "# trajroid configuration written by `trajroi sim` for scenario '%s'.\n"
                "# Replays this folder: trajroid --config <this folder>/trajroid.yaml --replay <this folder>\n"
                "# Relative paths are relative to this file.\n"
                "global_frame:\n"
                "  origin: {lat_deg: %.9f, lon_deg: %.9f, height_m: %.4f}\n"
                "trajectory:\n"
                "  file: %s\n"
                "lidar:\n"
                "  model: vlp16\n"
                "  mounting: {xyz: [%.4f, %.4f, %.4f], roll_deg: %.4f, pitch_deg: %.4f, yaw_deg: %.4f}\n"
                "  min_range_m: %.3f\n"
                "  max_range_m: %.3f\n"
                "gnss:\n"
                "  antenna: [%.4f, %.4f, %.4f]\n"
                "  delay_s: %.6f    # epoch → receipt of its NAV-PVT (latency + transmission)\n"
                "imu:\n"
                "  magnetic_declination_deg: %.4f\n"
                "  delay_s: %.6f    # sample → receipt of its frame\n"
                "roi:\n"
                "  shape: circular\n"
                "  circle_diameter_m: %.3f\n"
                "  rect_height_m: %.3f\n"
                "  rect_width_m: %.3f\n"
                "  spacing_ratio: 0.25\n"
                "  look_ahead_m: %.3f\n",
                s.name.c_str(), s.origin.lat_deg, s.origin.lon_deg, s.origin.height_m, kTrajectoryFile, m.xyz_m.x(),
                m.xyz_m.y(), m.xyz_m.z(), m.roll_rad * kRadToDeg, m.pitch_rad * kRadToDeg, m.yaw_rad * kRadToDeg,
                s.lidar.min_range_m, s.lidar.max_range_m, s.robot.gnss_antenna_m.x(), s.robot.gnss_antenna_m.y(),
                s.robot.gnss_antenna_m.z(), gnss_delay_s(s.gnss), s.imu.magnetic_declination_deg, imu_delay_s(s.imu),
                e.circle_diameter_m, e.rect_height_m, e.rect_width_m, e.look_ahead_m);
  return text;
}

}  // namespace

RunReport write_run(const Scenario& scenario, const std::string& scenario_text, const fs::path& out_dir,
                    const std::function<void(double)>& progress) {
  const Simulator simulator(scenario);
  const fs::path target = fs::absolute(out_dir).lexically_normal();
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  fs::create_directories(parent);
  std::random_device entropy;
  std::string temp_name = ".";
  temp_name += target.filename().string();
  temp_name += ".partial-";
  temp_name += std::to_string(entropy());
  const fs::path temp = parent / temp_name;
  fs::create_directories(temp / "truth");
  RunReport report;
  try {
    const auto start = std::chrono::steady_clock::now();
    FolderSink sink(temp);
    report.stats = simulator.run(sink, progress);
    sink.close();
    report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_text(temp / kScenarioFile, scenario_text);
    write_text(temp / kTrajectoryFile, simulator.trajectory_csv());
    write_text(temp / kDaemonConfigFile, daemon_config(scenario));
    const SimulationStats& st = report.stats;
    char summary[1024];
    std::snprintf(summary, sizeof summary,
                  "scenario            %s\n"
                  "duration_s          %.3f\n"
                  "trajectory_m        %.3f\n"
                  "data_packets        %llu\n"
                  "position_packets    %llu\n"
                  "rays                %llu\n"
                  "points              %llu\n"
                  "points_in_corridor  %llu\n"
                  "gnss_epochs         %llu\n"
                  "imu_frames          %llu\n"
                  "wall_s              %.3f\n"
                  "realtime_factor     %.2f\n",
                  scenario.name.c_str(), static_cast<double>(st.duration_ns) * 1e-9, simulator.path().length_m(),
                  static_cast<unsigned long long>(st.data_packets),
                  static_cast<unsigned long long>(st.position_packets), static_cast<unsigned long long>(st.rays),
                  static_cast<unsigned long long>(st.points), static_cast<unsigned long long>(st.points_in_corridor),
                  static_cast<unsigned long long>(st.gnss_epochs), static_cast<unsigned long long>(st.imu_frames),
                  report.wall_s, report.realtime_factor());
    write_text(temp / kSummaryFile, summary);
    if (fs::exists(target)) fs::remove_all(target);
    fs::rename(temp, target);
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(temp, ignored);
    throw;
  }
  return report;
}

TruthPoses::TruthPoses(const fs::path& file) {
  const std::vector<std::uint8_t> bytes = read_all(file);
  const std::span<const std::uint8_t> b(bytes);
  if (b.size() < 16 || std::memcmp(b.data(), kPosesMagic, 8) != 0 || framing::le_u32(b, 8) != kTruthVersion ||
      framing::le_u32(b, 12) != kPoseRecordBytes) {
    throw std::runtime_error(file.string() + ": not a trajroi truth pose file");
  }
  if ((b.size() - 16) % kPoseRecordBytes != 0) throw std::runtime_error(file.string() + ": cut inside a record");
  poses_.reserve((b.size() - 16) / kPoseRecordBytes);
  for (std::size_t at = 16; at < b.size(); at += kPoseRecordBytes) {
    poses_.push_back({static_cast<std::int64_t>(framing::le_u64(b, at)), framing::le_f64(b, at + 8),
                      framing::le_f64(b, at + 16), framing::le_f64(b, at + 24)});
  }
  if (poses_.empty()) throw std::runtime_error(file.string() + ": holds no pose");
}

TruePose TruthPoses::at(std::int64_t t_ns) const noexcept {
  auto it = std::lower_bound(poses_.begin(), poses_.end(), t_ns,
                             [](const TruePose& p, std::int64_t t) { return p.t_ns < t; });
  if (it == poses_.begin()) return poses_.front();
  if (it == poses_.end()) return poses_.back();
  const TruePose& b = *it;
  const TruePose& a = *std::prev(it);
  const double f = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  const double dyaw = std::remainder(b.yaw_rad - a.yaw_rad, 2.0 * std::numbers::pi);
  return {t_ns, a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m), a.yaw_rad + f * dyaw};
}

std::vector<std::uint8_t> read_truth_labels(const fs::path& file) {
  const std::vector<std::uint8_t> bytes = read_all(file);
  const std::span<const std::uint8_t> b(bytes);
  if (b.size() < 24 || std::memcmp(b.data(), kLabelsMagic, 8) != 0 || framing::le_u32(b, 8) != kTruthVersion) {
    throw std::runtime_error(file.string() + ": not a trajroi truth label file");
  }
  const std::uint64_t count = framing::le_u64(b, 16);
  if ((b.size() - 24) * 8 < count || (b.size() - 24) > count / 8 + 1) {
    throw std::runtime_error(file.string() + ": its size does not match its point count");
  }
  std::vector<std::uint8_t> labels(count);
  for (std::uint64_t i = 0; i < count; ++i)
    labels[i] = static_cast<std::uint8_t>((unsigned{b[24 + i / 8]} >> (i % 8)) & 1U);
  return labels;
}

void require_run_folder(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": not a folder");
  for (const char* name :
       {kScenarioFile, kLidarFile, kGnssFile, kImuFile, kTrajectoryFile, kTruthPosesFile, kTruthLabelsFile}) {
    if (!fs::is_regular_file(dir / name)) {
      throw std::runtime_error(dir.string() + ": not a scenario run folder (no " + name +
                               "; make one with `trajroi sim --scenario FILE.yaml --out DIR`)");
    }
  }
}

}  // namespace trajroi::sim
