#pragma once

// From the GNSS and IMU byte streams to the pose buffer: frames UBX and VN-100 bytes, decodes
// NAV-HPPOSLLH / NAV-PVT and the VN-100 attitude, places them in the global frame and stamps
// them in the host clock. Pure: bytes and receive times in, samples into a PoseBuffer out.
//
// Time. A sample is stamped with its sensor time (UBX iTOW, VN-100 TimeStartup or TimeGps)
// mapped onto the host clock by ClockMap — host = sensor + min(receive − sensor) − delay — so
// serial jitter does not reach the pose; `delay` is the known part of the transport (epoch to
// the message's receipt) that the minimum cannot see. A VN-100 output without a time field
// (common: YawPitchRoll alone) is placed at its receive time minus the delay.
//
// Attitude. From the IMU (pose.source gnss_imu): the VN-100 output's YawPitchRoll,
// Quaternion or DCM, whichever it carries (in that order). From the GNSS alone (pose.source
// gnss): the yaw of a moving-base baseline (NAV-RELPOSNED relPosHeading, valid) of the same
// epoch, else the course over ground above a speed; roll and pitch zero. Without either the
// last heading is held; before the first, a configured initial heading, else none (the pose
// gate then reports no attitude). heading_source() says which is in use.
//
// Position. NAV-PVT closes an epoch: its position comes from the NAV-HPPOSLLH of the same
// iTOW when one came before it (0.1 mm instead of 1 cm), else from NAV-PVT itself; its
// quality (fix type, gnssFixOK, carrier solution, hAcc) goes with it to the pose gate. An
// epoch flagged invalidLlh keeps the last position with its own (failing) quality, so the
// gate reports a lost fix rather than a gap.
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "trajroi/framing/protocol_sniffer.hpp"
#include "trajroi/pose/attitude.hpp"
#include "trajroi/pose/geodetic.hpp"
#include "trajroi/pose/pose_buffer.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::pose_input {

// host ≈ sensor + offset, offset = the least (receive − sensor) seen since the last reset.
// A sensor time that goes backwards, or a receive time further than `reset_threshold_ns`
// from the mapped time, resets the map (counted).
class ClockMap {
 public:
  explicit ClockMap(std::int64_t reset_threshold_ns = 1'000'000'000) noexcept : threshold_ns_(reset_threshold_ns) {}
  [[nodiscard]] std::int64_t map(std::int64_t sensor_ns, std::int64_t receive_ns) noexcept;
  [[nodiscard]] std::uint64_t resets() const noexcept { return resets_; }

 private:
  std::int64_t threshold_ns_;
  std::optional<std::int64_t> offset_ns_;
  std::int64_t last_sensor_ns_ = 0;
  std::uint64_t resets_ = 0;
};

enum class AttitudeFrom : std::uint8_t { kImu, kGnss };

enum class HeadingSource : std::uint8_t {
  kNone,          // no attitude yet
  kImu,           // the VN-100's attitude
  kBaseline,      // NAV-RELPOSNED moving-base heading
  kCourse,        // NAV-PVT course over ground
  kHeld,          // the last GNSS heading, held while neither is usable (slow, or no baseline)
  kConfigured,    // the configured initial heading, before the GNSS gave one
  kLocalization,  // the robot's localization (pose.source lcm)
};
[[nodiscard]] std::string_view to_string(HeadingSource source) noexcept;

struct PoseInputConfig {
  pose::ImuMounting imu;
  std::int64_t gnss_delay_ns = 0;  // epoch → receipt of its NAV-PVT
  std::int64_t imu_delay_ns = 0;   // sample → receipt of its frame
  AttitudeFrom attitude = AttitudeFrom::kImu;
  pose::HeadingFallback heading;              // with AttitudeFrom::kGnss
  std::optional<double> initial_heading_deg;  // true bearing, until the GNSS gives a heading
};

struct PoseInputCounters {
  std::uint64_t fixes = 0;             // NAV-PVT epochs given to the buffer
  std::uint64_t high_precision = 0;    // … of which placed with NAV-HPPOSLLH
  std::uint64_t invalid_position = 0;  // epochs flagged invalidLlh, or off the WGS-84 range / the frame
  std::uint64_t malformed = 0;         // framed UBX/VN-100 that did not decode
  std::uint64_t attitudes = 0;
  std::uint64_t imu_without_attitude = 0;  // frames carrying no YawPitchRoll, Quaternion or DCM
  std::uint64_t imu_receive_stamped = 0;   // … with an attitude but no sensor time (placed at receipt)
  std::uint64_t gnss_headings = 0;         // attitudes made from the GNSS (course, baseline, held)
  std::uint64_t ubx_other = 0;             // well-formed UBX messages not used (neither PVT nor HPPOSLLH / RELPOSNED)
  std::uint64_t refused = 0;               // samples the buffer refused (order, non-finite)
  std::uint64_t vn100_frames_on_gnss = 0;  // VN-100 frames among the GNSS bytes (devices swapped?)
  std::uint64_t ubx_frames_on_imu = 0;     // UBX frames among the IMU bytes
  std::uint64_t external_poses = 0;        // localization poses used (pose.source lcm)
  std::uint64_t external_invalid = 0;      // … flagged invalid by the localizer, or off the frame
};

// A pose from the robot's own localization (pose.source lcm), already on the host clock.
struct ExternalPose {
  std::int64_t t_ns = 0;
  bool lat_lon = false;                                             // position is lat_deg, lon_deg, height_m
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               // global frame m, or geodetic
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // global_from_robot (ENU at the robot)
  bool valid = false;
};

class PoseInput {
 public:
  PoseInput(pose::GlobalFrame frame, const PoseInputConfig& config, pose::PoseBuffer& buffer);

  void gnss_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns);
  void imu_bytes(std::span<const std::uint8_t> bytes, std::int64_t receive_ns);
  // Already framed and decoded (for callers that frame themselves).
  void on_ubx(const ublox::Message& message, std::int64_t receive_ns);
  void on_vn100(const vn100::Sample& sample, std::int64_t receive_ns);
  // A localization pose: its position as a fix that passes every gate (the localizer vouches
  // for it), its orientation as an attitude. Invalid ones are counted, not used.
  void on_external_pose(const ExternalPose& pose);

  [[nodiscard]] const PoseInputCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const framing::FramerCounters& gnss_framing() const noexcept { return ubx_.counters(); }
  [[nodiscard]] const framing::FramerCounters& imu_framing() const noexcept { return vn_.counters(); }
  // What else each port carried (NMEA, VectorNav ASCII, RTCM3) while it gave no frame of its own.
  [[nodiscard]] const framing::SnifferCounters& gnss_sniffed() const noexcept { return gnss_sniffer_.counters(); }
  [[nodiscard]] const framing::SnifferCounters& imu_sniffed() const noexcept { return imu_sniffer_.counters(); }
  [[nodiscard]] const ClockMap& gnss_clock() const noexcept { return gnss_clock_; }
  [[nodiscard]] const ClockMap& imu_clock() const noexcept { return imu_clock_; }
  [[nodiscard]] HeadingSource heading_source() const noexcept { return heading_source_; }
  // The newest NAV-PVT with a valid, resolved UTC: that UTC (ns since 1970) and the epoch's
  // host time (monotonic ns), for the host clock's offset from GNSS time.
  struct GnssUtc {
    std::int64_t utc_ns = 0;
    std::int64_t host_ns = 0;
    std::uint32_t accuracy_ns = 0;  // NAV-PVT tAcc
  };
  [[nodiscard]] const std::optional<GnssUtc>& gnss_utc() const noexcept { return gnss_utc_; }
  // The newest NAV-PVT decoded (the rover's position for a VRS caster's GGA, the carrier
  // solution for the status) and how many have been (a change means a new one).
  [[nodiscard]] const std::optional<ublox::NavPvt>& newest_pvt() const noexcept { return newest_pvt_; }
  [[nodiscard]] std::uint64_t pvt_count() const noexcept { return pvt_count_; }

 private:
  void gnss_heading(const ublox::NavPvt& pvt, std::int64_t t_ns);
  bool add_attitude(const Eigen::Quaterniond& global_from_robot, std::int64_t t_ns);

  pose::GlobalFrame frame_;
  PoseInputConfig config_;
  pose::PoseBuffer& buffer_;
  ublox::Framer ubx_;
  vn100::Framer vn_;
  // The other sensor's framer on each port, to tell swapped devices from a wrong baud rate.
  ublox::Framer ubx_on_imu_;
  vn100::Framer vn_on_gnss_;
  framing::ProtocolSniffer gnss_sniffer_, imu_sniffer_;
  ClockMap gnss_clock_;
  ClockMap imu_clock_;
  std::optional<ublox::NavHpposllh> hp_;
  std::optional<ublox::NavRelposned> relpos_;
  std::optional<double> heading_yaw_rad_;  // the last GNSS (or configured) heading, global yaw
  HeadingSource heading_source_ = HeadingSource::kNone;
  std::optional<GnssUtc> gnss_utc_;
  std::optional<ublox::NavPvt> newest_pvt_;
  std::uint64_t pvt_count_ = 0;
  std::optional<pose::Geodetic> last_position_;
  std::optional<Eigen::Vector3d> last_global_;  // last_position_ in the global frame
  PoseInputCounters counters_;
};

}  // namespace trajroi::pose_input
