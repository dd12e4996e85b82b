#include "trajroi/pipeline/pose_words.hpp"

#include <cstdio>

namespace trajroi::pipeline {

pose::PoseWords pose_words(PoseSource source) noexcept {
  switch (source) {
    case PoseSource::kGnssImu:
      return {.fix = "GNSS fix", .fixes = "GNSS fixes", .attitude = "IMU attitude", .attitudes = "IMU attitudes"};
    case PoseSource::kGnss:
      return {.fix = "GNSS fix", .fixes = "GNSS fixes", .attitude = "GNSS heading", .attitudes = "GNSS headings"};
    case PoseSource::kLcm:
      return {.fix = "localization pose",
              .fixes = "localization poses",
              .attitude = "localization pose",
              .attitudes = "localization poses"};
    case PoseSource::kFixed:
      break;
  }
  return {.fix = "fixed pose", .fixes = "fixed poses", .attitude = "fixed pose", .attitudes = "fixed poses"};
}

std::string_view pose_source_name(PoseSource source) noexcept {
  return source == PoseSource::kLcm ? std::string_view("localization") : to_string(source);
}

std::string pose_reason(pose::PoseStatus status, double measured, double limit, const DaemonConfig& config) {
  std::string text = pose::describe(status, measured, limit, pose_words(config.pose_source));
  const auto device = [](const char* key, const DaemonConfig::Serial& s) {
    return s.device.empty() ? std::string(" (") + key + " is not set)" : std::string(" from ") + key + " " + s.device;
  };
  switch (status) {
    case pose::PoseStatus::kNoGnss:
      if (uses_gnss(config.pose_source)) {
        text += device("gnss.device", config.gnss);
      } else if (config.pose_source == PoseSource::kLcm) {
        text += " on " + config.lcm.pose_input + " (lcm.channels.pose_input)";
      }
      break;
    case pose::PoseStatus::kNoAttitude:
      if (config.pose_source == PoseSource::kGnssImu) {
        text += device("imu.device", config.imu);
      } else if (config.pose_source == PoseSource::kGnss) {
        char more[240];
        std::snprintf(more, sizeof more,
                      ": the robot has not moved faster than pose.gnss_heading.min_speed_mps (%.2f m/s) and no "
                      "moving-base heading came; to start parked, set pose.gnss_heading.initial_heading_deg",
                      config.gnss_heading.min_speed_mps);
        text += more;
      }
      break;
    case pose::PoseStatus::kBeforeFirstSample:
      text +=
          " (the sweep is older than the pose history kept: pose.buffer_samples, or the sensor's time "
          "is behind the pose inputs')";
      break;
    default:
      break;
  }
  return text;
}

}  // namespace trajroi::pipeline
