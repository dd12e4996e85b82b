#pragma once

// The robot's pose over time: GNSS fixes (antenna position in the global frame, with their
// quality) and attitudes (global_from_robot rotations), each ordered by host time in ns.
// pose_at(t) interpolates (position linear, attitude slerp) between the samples around t,
// extrapolates at most a configured bound past the newest one, and otherwise answers
// "no valid pose" with the reason — it never hands out a stale or low-quality pose silently.
//
// The robot origin is placed from the antenna with the lever arm:
//   p_global_robot = p_global_antenna − R_global_robot · p_robot_antenna.
//
// Storage is preallocated (capacity per stream); the oldest samples are dropped first.
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace trajroi::pose {

// The carrier-phase (RTK) solution of a fix, worst to best (NAV-PVT carrSoln).
enum class RtkSolution : std::uint8_t { kNone, kFloat, kFixed };
[[nodiscard]] std::string_view to_string(RtkSolution s) noexcept;  // "none", "float", "fixed"

// Quality of a GNSS fix, as the receiver reported it (u-blox NAV-PVT semantics).
struct FixQuality {
  std::uint8_t fix_type = 0;  // 0 none, 1 DR, 2 2-D, 3 3-D, 4 GNSS+DR, 5 time only
  bool gnss_fix_ok = false;
  double h_acc_m = 1e9;
  bool rtk_fixed = false;  // carrier solution fixed
  bool rtk_float = false;
  [[nodiscard]] RtkSolution rtk() const noexcept {
    return rtk_fixed ? RtkSolution::kFixed : rtk_float ? RtkSolution::kFloat : RtkSolution::kNone;
  }
};

struct GnssFix {
  std::int64_t t_ns = 0;  // host monotonic time of the epoch
  Eigen::Vector3d antenna_global_m = Eigen::Vector3d::Zero();
  FixQuality quality;
};

struct AttitudeSample {
  std::int64_t t_ns = 0;
  Eigen::Quaterniond global_from_robot = Eigen::Quaterniond::Identity();
};

struct PoseGate {
  std::uint8_t min_fix_type = 3;  // 3-D (4 = GNSS + dead reckoning also passes)
  bool require_gnss_fix_ok = true;
  double max_h_acc_m = 0.5;
  RtkSolution require_rtk = RtkSolution::kNone;     // at least this carrier solution
  std::int64_t max_extrapolation_ns = 100'000'000;  // past the newest sample of each stream
  std::int64_t max_gap_ns = 1'000'000'000;          // between the two samples bracketing t
};

enum class PoseStatus : std::uint8_t {
  kValid,
  kNoGnss,             // no fix at all yet
  kNoAttitude,         // no attitude at all yet
  kBeforeFirstSample,  // t precedes the oldest sample kept
  kGnssTooOld,         // t is past the newest fix by more than max_extrapolation_ns
  kAttitudeTooOld,
  kGnssGap,  // the fixes around t are further apart than max_gap_ns
  kAttitudeGap,
  kFixTypeTooLow,  // a fix used fails the gate …
  kNoGnssFixOk,
  kAccuracyTooLow,
  kRtkTooLow,  // carrier solution worse than require_rtk (measured / limit: RtkSolution)
};
[[nodiscard]] std::string_view to_string(PoseStatus status) noexcept;

struct PoseQuery {
  PoseStatus status = PoseStatus::kNoGnss;
  Eigen::Isometry3d global_from_robot = Eigen::Isometry3d::Identity();  // valid only if kValid
  // For a failed gate, the figure that failed and its limit (fix type; h_acc m; age or gap s).
  double measured = 0.0;
  double limit = 0.0;
  [[nodiscard]] bool valid() const noexcept { return status == PoseStatus::kValid; }
};
// What the two streams of the buffer are called in texts, as the pose source has them: GNSS
// fixes and attitudes by default; a robot's localization fills both with its poses.
struct PoseWords {
  std::string_view fix = "GNSS fix";
  std::string_view fixes = "GNSS fixes";
  std::string_view attitude = "attitude";
  std::string_view attitudes = "attitudes";
};
// The status with its figures, e.g. "GNSS horizontal accuracy 2.52 m > limit 0.50 m
// (pose.max_h_acc_m)"; the status text alone where it has none; in `words`.
[[nodiscard]] std::string describe(PoseStatus status, double measured, double limit, const PoseWords& words = {});

// Counts of samples refused on insertion.
struct PoseBufferCounters {
  std::uint64_t fixes = 0;
  std::uint64_t attitudes = 0;
  std::uint64_t out_of_order = 0;  // older than or as old as the newest sample of its stream
  std::uint64_t non_finite = 0;    // NaN / infinite values
};

class PoseBuffer {
 public:
  // `capacity` samples per stream (at least 2). Throws std::invalid_argument for a gate
  // with negative bounds or a capacity below 2.
  PoseBuffer(const PoseGate& gate, const Eigen::Vector3d& antenna_in_robot_m, std::size_t capacity = 256);

  // Samples must arrive in increasing time per stream; others are refused and counted.
  bool add_fix(const GnssFix& fix) noexcept;
  bool add_attitude(const AttitudeSample& attitude) noexcept;

  [[nodiscard]] PoseQuery pose_at(std::int64_t t_ns) const noexcept;

  // A static pose (pose.source fixed: a parked sensor, a bench, a LiDAR-only replay): from now
  // on pose_at() answers it, valid, at every time; the samples are not consulted.
  void hold(const Eigen::Isometry3d& global_from_robot) noexcept { held_ = global_from_robot; }

  [[nodiscard]] const PoseBufferCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const PoseGate& gate() const noexcept { return gate_; }
  // The newest fix, or nullptr before the first.
  [[nodiscard]] const GnssFix* newest_fix() const noexcept { return fixes_.size > 0 ? &fixes_.newest() : nullptr; }
  // The newest attitude's time, or nullopt before the first.
  [[nodiscard]] std::optional<std::int64_t> newest_attitude_ns() const noexcept {
    return attitudes_.size > 0 ? std::optional<std::int64_t>(attitudes_.newest().t_ns) : std::nullopt;
  }

 private:
  template <class T>
  struct Ring {
    std::vector<T> items;  // grows to `capacity` (reserved), then is written over
    std::size_t capacity = 0;
    std::size_t head = 0;  // index of the oldest
    std::size_t size = 0;
    [[nodiscard]] const T& at(std::size_t i) const noexcept {
      const std::size_t k = head + i;  // head, i < items.size(): one wrap at most, no division
      return items[k < items.size() ? k : k - items.size()];
    }
    [[nodiscard]] const T& newest() const noexcept { return at(size - 1); }
    void push(const T& item) noexcept;
    // Index of the last sample with time ≤ t, or size when t precedes every sample. Queries
    // come near the newest samples (a sweep's firings, as the samples arrive): those are
    // looked at first, then the rest is bisected.
    [[nodiscard]] std::size_t floor(std::int64_t t_ns) const noexcept;
  };

  // kValid, or the failing status with its figure and limit in `out`.
  [[nodiscard]] PoseStatus check(const FixQuality& q, PoseQuery& out) const noexcept;

  // The parts of Eigen's slerp (Quaternion.h) that depend only on the two attitudes: their
  // dot product, the angle between them and its sine. Each attitude keeps those of the pair it
  // ends, taken once as it arrives instead of at every interpolation inside the pair.
  struct SlerpPair {
    double dot = 1.0;
    double theta = 0.0;
    double sin_theta = 0.0;
    bool linear = true;  // |dot| ≥ 1 − ε: Eigen interpolates the coefficients linearly
  };
  // Also what a query held at this attitude (the newest, within the extrapolation bound: most
  // queries, as the IMU's frames come after the points they cover) computes from it alone: its
  // rotation matrix and the lever arm turned by it, taken once as it arrives.
  struct StoredAttitude : AttitudeSample {
    SlerpPair from_previous;
    Eigen::Matrix3d rotation;
    Eigen::Vector3d lever_arm_global_m;
  };

  // Also the velocity from the previous fix, when a query after this fix extrapolates with it
  // (the two close enough, the previous passing the gate): taken once as it arrives.
  struct StoredFix : GnssFix {
    bool extrapolates = false;
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/ns
  };

  PoseGate gate_;
  Eigen::Vector3d antenna_in_robot_m_;
  Ring<StoredFix> fixes_;
  Ring<StoredAttitude> attitudes_;
  PoseBufferCounters counters_;
  std::optional<Eigen::Isometry3d> held_;
};

}  // namespace trajroi::pose

namespace trajroi::pose {

// The sensor's pose for each firing of a sweep, queried once per firing period (a VLP-16
// firing sequence, 55.296 µs) as the points come in time order: every point of one firing
// gets the same global_from_sensor, so motion is compensated per firing, not per point.
class FiringPoses {
 public:
  FiringPoses(const PoseBuffer& buffer, const Eigen::Isometry3d& robot_from_sensor, std::int64_t period_ns) noexcept
      : buffer_(&buffer), robot_from_sensor_(robot_from_sensor), period_ns_(period_ns) {}

  // The times the last query's pose is kept for, [t_query, t_query + period), as offsets after
  // a base time (a frame's start: its points carry such offsets): one unsigned comparison each.
  struct Window {
    std::int64_t first_ns;
    std::uint64_t period_ns;
    [[nodiscard]] bool contains(std::int64_t offset_ns) const noexcept {
      return static_cast<std::uint64_t>(offset_ns - first_ns) < period_ns;
    }
  };
  // Meaningful once at() has made a query.
  [[nodiscard]] Window window_after(std::int64_t base_ns) const noexcept {
    return {query_ns_ - base_ns, static_cast<std::uint64_t>(period_ns_)};
  }

  // global_from_sensor at t, or nullptr when the pose is not valid (`status` says why). A new
  // query is made when t leaves the last query's window.
  [[nodiscard]] const Eigen::Isometry3d* at(std::int64_t t_ns, PoseStatus& status) noexcept {
    if (!have_ || !window_after(0).contains(t_ns)) {
      const PoseQuery q = buffer_->pose_at(t_ns);
      status_ = q.status;
      measured_ = q.measured;
      limit_ = q.limit;
      have_ = true;
      query_ns_ = t_ns;
      if (q.valid()) place_sensor(q.global_from_robot);
    }
    status = status_;
    return status_ == PoseStatus::kValid ? &global_from_sensor_ : nullptr;
  }
  // global_from_sensor_ = global_from_robot * robot_from_sensor_ as Eigen computes it
  // (linear: the rotations' product; translation: R · sensor offset, then + robot position),
  // the parts that depend on the rotation alone kept from the last query when it is the same.
  void place_sensor(const Eigen::Isometry3d& global_from_robot) noexcept {
    if (global_from_robot.linear() != last_robot_rotation_) {
      last_robot_rotation_ = global_from_robot.linear();
      global_from_sensor_.linear() = global_from_robot.linear() * robot_from_sensor_.linear();
      turned_sensor_offset_ = global_from_robot.linear() * robot_from_sensor_.translation();
    }
    global_from_sensor_.translation() = turned_sensor_offset_ + global_from_robot.translation();
  }
  // The last query's failing figure and its limit (PoseQuery::measured, limit).
  [[nodiscard]] double measured() const noexcept { return measured_; }
  [[nodiscard]] double limit() const noexcept { return limit_; }
  void reset() noexcept { have_ = false; }

 private:
  const PoseBuffer* buffer_;
  Eigen::Isometry3d robot_from_sensor_;
  std::int64_t period_ns_;
  bool have_ = false;
  std::int64_t query_ns_ = 0;
  PoseStatus status_ = PoseStatus::kNoGnss;
  double measured_ = 0.0, limit_ = 0.0;
  Eigen::Isometry3d global_from_sensor_ = Eigen::Isometry3d::Identity();
  // The last product's rotation part: while the robot's attitude is the same (held between
  // IMU frames), global_from_sensor's rotation and the turned sensor offset are too.
  Eigen::Matrix3d last_robot_rotation_ = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d turned_sensor_offset_ = Eigen::Vector3d::Zero();
};

}  // namespace trajroi::pose
