#pragma once

// The folder a simulation run is written to (and every evaluation and replay reads):
//   scenario.yaml      the scenario, as given
//   lidar.pcap         VLP-16 data (UDP 2368) and position (UDP 8308) packets, Ethernet, ns
//   gnss.trjb          u-blox NAV-HPPOSLLH + NAV-PVT, a timestamped byte recording
//   imu.trjb           VN-100 binary frames, a timestamped byte recording
//   trajectory.csv     the target trajectory (x,y per line, global frame)
//   trajroid.yaml      a trajroid configuration that replays the run
//   truth/poses.bin    the robot's true pose at every firing sequence
//   truth/labels.bin   per decoded point (decoder order), 1 when it is in the ground-truth
//                      corridor of the whole trajectory (evaluation.corridor_width_m)
//   summary.txt        what was generated, and how fast
//
// truth/poses.bin: "TRJPOSES", uint32 version (1), uint32 record size (32), then records of
//   int64 t_ns (scenario UTC), float64 x_m, float64 y_m, float64 yaw_rad; little-endian.
// truth/labels.bin: "TRJLABEL", uint32 version (1), uint32 0, uint64 point count, then the
//   labels one bit each, least significant bit first.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "trajroi/sim/simulator.hpp"

namespace trajroi::sim {

inline constexpr const char* kScenarioFile = "scenario.yaml";
inline constexpr const char* kLidarFile = "lidar.pcap";
inline constexpr const char* kGnssFile = "gnss.trjb";
inline constexpr const char* kImuFile = "imu.trjb";
inline constexpr const char* kTrajectoryFile = "trajectory.csv";
inline constexpr const char* kDaemonConfigFile = "trajroid.yaml";
inline constexpr const char* kTruthPosesFile = "truth/poses.bin";
inline constexpr const char* kTruthLabelsFile = "truth/labels.bin";
inline constexpr const char* kSummaryFile = "summary.txt";

struct RunReport {
  SimulationStats stats;
  double wall_s = 0.0;
  [[nodiscard]] double realtime_factor() const noexcept {
    return wall_s > 0.0 ? static_cast<double>(stats.duration_ns) * 1e-9 / wall_s : 0.0;
  }
};

// Simulates `scenario` (whose YAML text is `scenario_text`) into `out_dir`. Everything is
// written to a sibling temporary folder first and renamed over `out_dir` at the end, so a
// failure leaves no half-written run (and an earlier run in its place). Throws
// std::runtime_error naming the file on any I/O error.
RunReport write_run(const Scenario& scenario, const std::string& scenario_text, const std::filesystem::path& out_dir,
                    const std::function<void(double)>& progress = {});

// The truth files, read back. Throws std::runtime_error naming the file when it is missing,
// not of its format, or cut short.
class TruthPoses {
 public:
  explicit TruthPoses(const std::filesystem::path& file);
  [[nodiscard]] const std::vector<TruePose>& poses() const noexcept { return poses_; }
  // The pose at t, linear between the firing sequences around it (yaw unwrapped); clamped
  // at the ends.
  [[nodiscard]] TruePose at(std::int64_t t_ns) const noexcept;

 private:
  std::vector<TruePose> poses_;
};

[[nodiscard]] std::vector<std::uint8_t> read_truth_labels(const std::filesystem::path& file);

// Checks that `dir` holds a run (every file above); throws std::runtime_error saying which
// file is missing otherwise.
void require_run_folder(const std::filesystem::path& dir);

}  // namespace trajroi::sim
