#pragma once

// Where `trajroi export` takes its sweeps from: an LCM log of trajroid's points_t (lcm-logger,
// or trajroid's file:// LCM URL), or a run folder (lidar.pcap, gnss.trjb, imu.trjb and its
// trajroid.yaml) replayed through the per-sweep pipeline as fast as it reads.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "trajroi/cloud_io/cloud.hpp"

namespace trajroi::cli {

struct ExportSweep {
  const cloud_io::Cloud& cloud;
  std::int64_t index;
  std::int64_t start_ns;  // host clock
};

struct SourceSummary {
  std::uint64_t sweeps = 0;
  std::string skipped;  // what was left out, in words ("" when nothing)
  std::string cut;      // an LCM log cut short: where (its sweeps before the cut are exported)
};

using SweepHandler = std::function<void(const ExportSweep&)>;
// progress(fraction done 0…1, sweeps so far)
using Progress = std::function<void(double, std::uint64_t)>;

// The points_t on `channel` of an LCM log; other channels and types skipped and counted.
SourceSummary read_lcm_log(const std::filesystem::path& log, const std::string& channel, const SweepHandler& on_sweep,
                           const Progress& progress);

// The run folder replayed through SweepProcessor with `config` (a trajroid.yaml; the folder's
// own when empty): the sweeps trajroid would publish (a sweep without a valid pose withheld
// and counted). Throws naming a missing recording or a bad configuration.
SourceSummary replay_run_folder(const std::filesystem::path& dir, const std::filesystem::path& config,
                                const SweepHandler& on_sweep, const Progress& progress);

}  // namespace trajroi::cli
