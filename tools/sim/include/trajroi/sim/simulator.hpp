#pragma once

// The scenario simulator: drives the robot along its path and produces what its sensors
// would send — VLP-16 data and position packets ray-cast against the world with the real
// firing schedule (every laser at its own time, so motion during a sweep is in the data),
// u-blox NAV-HPPOSLLH + NAV-PVT epochs and VN-100 binary frames — each stamped with the time
// a host would receive it, plus the ground truth. Pure: everything goes to a sink.
//
// Time: one clock for every stream, the UTC of the scenario (the first firing at
// start_utc). Pcap records carry the time a packet's last firing ends; serial chunks the
// time their last byte arrives (epoch + latency + bytes × 10 / baud).
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "trajroi/roi/trajectory.hpp"
#include "trajroi/sim/path.hpp"
#include "trajroi/sim/scenario.hpp"
#include "trajroi/sim/world.hpp"

namespace trajroi::sim {

// The robot's true pose (on the ground, z = 0) at one firing sequence of the VLP-16.
struct TruePose {
  std::int64_t t_ns;  // scenario UTC of the sequence's first laser
  double x_m;
  double y_m;
  double yaw_rad;
};

class SimulationSink {
 public:
  virtual ~SimulationSink() = default;
  virtual void lidar_datagram(std::int64_t receive_ns, std::uint16_t port, std::span<const std::uint8_t> payload) = 0;
  virtual void gnss_chunk(std::int64_t receive_ns, std::span<const std::uint8_t> bytes) = 0;
  virtual void imu_chunk(std::int64_t receive_ns, std::span<const std::uint8_t> bytes) = 0;
  // One per firing sequence, in time order.
  virtual void firing_pose(const TruePose& pose) = 0;
  // For one data packet: 1 per point the decoder will give (in its order) whose measured
  // position, placed with the true pose, lies in the scenario's ground-truth corridor.
  virtual void point_labels(std::span<const std::uint8_t> labels) = 0;
};

struct SimulationStats {
  std::int64_t duration_ns = 0;
  std::uint64_t data_packets = 0;
  std::uint64_t position_packets = 0;
  std::uint64_t rays = 0;
  std::uint64_t points = 0;  // returns the decoder will give
  std::uint64_t points_in_corridor = 0;
  std::uint64_t gnss_epochs = 0;
  std::uint64_t imu_frames = 0;
};

class Simulator {
 public:
  explicit Simulator(const Scenario& scenario);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  [[nodiscard]] const Scenario& scenario() const noexcept;
  [[nodiscard]] const Path& path() const noexcept;
  // The trajectory file's text and the trajectory parsed back from it (what every consumer
  // of the run reads).
  [[nodiscard]] const std::string& trajectory_csv() const noexcept;
  [[nodiscard]] const roi::Trajectory& trajectory() const noexcept;

  // Runs the whole scenario into `sink`. `progress(fraction)` is called now and then.
  SimulationStats run(SimulationSink& sink, const std::function<void(double)>& progress = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace trajroi::sim
