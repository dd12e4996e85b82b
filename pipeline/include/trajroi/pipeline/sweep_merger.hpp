#pragma once

// Several LiDARs' sweeps made into one: each sensor's sweep, filtered against the ROI on its
// own lane, joins the window the first sweep after the previous merge opened; the window goes
// out as one sweep (the kept points of all, each with its sensor's index) when every sensor
// that is not silent has given one, when one gives a second, or when the input time passes
// max_wait after the window opened. A sensor with no sweep for silent_s is not waited for.
// Input time only (the items' receive times): a replay merges as the live run did.
// Or, per sensor: each sweep goes out alone, its points marked with its sensor.
#include <cstdint>
#include <vector>

#include "trajroi/pipeline/sweep.hpp"

namespace trajroi::pipeline {

struct MergeOptions {
  std::int64_t max_wait_ns = 100'000'000;
  std::int64_t silent_ns = 500'000'000;
  bool per_sensor = false;
};

class SweepMerger {
 public:
  // Room as each lane's sweep has (points, ROI centres, raw points), times the sensors when
  // merged.
  SweepMerger(std::size_t sensors, std::size_t points_per_sweep, std::size_t centres, std::size_t raw_points,
              MergeOptions options);

  // Sensor `sensor`'s sweep ended at input time `now_ns`: joins the window (its points are
  // copied; `sweep` is the lane's to reuse after the call).
  void add(std::size_t sensor, const Sweep& sweep, std::int64_t now_ns, SweepSink& sink);
  // The input time is `now_ns`: a window past its wait goes out.
  void tick(std::int64_t now_ns, SweepSink& sink);
  // The end of the input: the open window goes out.
  void flush(SweepSink& sink);

  // True when sensor `sensor` has given no sweep for silent_s at `now_ns` (counted from the
  // first input for one that never did).
  [[nodiscard]] bool silent(std::size_t sensor, std::int64_t now_ns) const noexcept;
  // Sweeps that went out without a sensor that was waited for.
  [[nodiscard]] std::uint64_t incomplete() const noexcept { return incomplete_; }
  // Sweeps that went out with points (a valid pose): the points_t messages.
  [[nodiscard]] std::uint64_t published() const noexcept { return published_; }
  // Reserves and touches the merged sweep (Sweep::make_resident).
  void make_resident() { merged_.make_resident(); }

 private:
  void emit(SweepSink& sink);
  void append(std::size_t sensor, const Sweep& sweep);

  MergeOptions options_;
  std::size_t capacity_;
  Sweep merged_;
  bool open_ = false;
  std::int64_t deadline_ns_ = 0;
  std::int64_t first_input_ns_ = 0;
  std::int64_t now_ns_ = 0;       // the newest input time seen
  std::int64_t joined_ns_ = 0;    // the input time the window's last sweep joined it
  std::uint32_t waited_for_ = 0;  // the sensors not silent when the window opened
  std::vector<std::int64_t> last_ns_;
  std::uint64_t index_ = 0;
  std::uint64_t incomplete_ = 0;
  std::uint64_t published_ = 0;
};

}  // namespace trajroi::pipeline
