#pragma once

// A pose's state in the words of the pose source in use: a localization gap is a gap between
// localization poses, never "GNSS"; a parked robot on GNSS alone is told which settings would
// give it a heading. Used for pose_t.status_text, status_t, the status line and the warnings
// about withheld sweeps.
#include <string>

#include "trajroi/daemon/config.hpp"
#include "trajroi/pose/pose_buffer.hpp"

namespace trajroi::pipeline {

using daemon::DaemonConfig;
using daemon::PoseSource;

// What the pose source's streams are called (PoseBuffer's fixes and attitudes).
[[nodiscard]] pose::PoseWords pose_words(PoseSource source) noexcept;

// The pose source as subscribers see it in pose_t and status_t: "gnss_imu", "gnss",
// "localization", "fixed".
[[nodiscard]] std::string_view pose_source_name(PoseSource source) noexcept;

// Whether the source's position is a GNSS fix (fix type, accuracy and RTK apply to it).
[[nodiscard]] constexpr bool uses_gnss(PoseSource source) noexcept {
  return source == PoseSource::kGnssImu || source == PoseSource::kGnss;
}

// Why there is no valid pose, with its figures, in the source's words, and where the cause is
// in the configuration the setting or the input that would change it.
[[nodiscard]] std::string pose_reason(pose::PoseStatus status, double measured, double limit,
                                      const DaemonConfig& config);

}  // namespace trajroi::pipeline
