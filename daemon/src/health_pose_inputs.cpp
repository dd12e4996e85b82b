// The health monitor's look at the pose source's inputs: the GNSS and IMU serial ports (silent,
// closed, or carrying something else than their binary protocol, named by what it is) and the
// robot's localization over LCM (stopped, back, invalid, undecodable).
#include "health.hpp"
#include "health_format.hpp"
#include "trajroi/pipeline/pose_words.hpp"

namespace trajroi::daemon {

namespace {

using C = Counter;

struct Port {
  const char* name;   // "gnss"
  const char* title;  // "GNSS", for the state
  const DaemonConfig::Serial* device;
  inputs::Stream stream;
  C bytes, frames, foreign_frames, nmea;  // nmea, then VN-100 ASCII, then RTCM3
  const char* protocol;                   // "UBX"
  const char* other;                      // the other sensor's protocol
};

}  // namespace

void HealthMonitor::serial_ports(const StatusSnapshot& s, std::vector<HealthLine>& out) {
  const bool gnss_used = pipeline::uses_gnss(config_.pose_source) && !config_.gnss.device.empty();
  const bool imu_used = config_.pose_source == PoseSource::kGnssImu && !config_.imu.device.empty();
  const Port ports[2] = {{"gnss", "GNSS", &config_.gnss, inputs::Stream::kGnss, C::kGnssBytes, C::kGnssFrames,
                          C::kGnssForeignFrames, C::kGnssNmea, "UBX", "VN-100"},
                         {"imu", "IMU", &config_.imu, inputs::Stream::kImu, C::kImuBytes, C::kImuFrames,
                          C::kImuForeignFrames, C::kImuNmea, "VN-100", "UBX"}};
  const Fault silent_faults[2] = {kGnssSilent, kImuSilent};
  const Fault garbage_faults[2] = {kGnssNoFrames, kImuNoFrames};
  const double window = window_s(s);
  for (int k = 0; k < 2; ++k) {
    const Port& p = ports[k];
    const bool used = k == 0 ? gnss_used : imu_used;
    const char* dev = p.device->device.c_str();
    serial_state_[k].clear();
    // A device that cannot be opened is said by its input (with errno) and retried: not also
    // "no bytes" (the same state twice, worded as if it were open).
    const bool closed = used && (s.closed_streams & (1U << static_cast<unsigned>(p.stream))) != 0;
    const auto d = [&](C c, int offset = 0) {
      return delta(s, static_cast<C>(static_cast<std::size_t>(c) + static_cast<std::size_t>(offset)));
    };
    if (closed) active_[silent_faults[k]] = false;
    set(silent_faults[k], live_ && used && !closed && judged(s) && d(p.bytes) == 0,
        sprintf_text("%s: no bytes for %.0f s from %s: receiver off, or its output on another port?", p.name, window,
                     dev),
        sprintf_text("%s: bytes arriving from %s", p.name, dev), out);
    if (active_[silent_faults[k]]) serial_state_[k] = sprintf_text("%s: no bytes from %s", p.title, dev);

    const bool garbage = used && judged(s) && d(p.bytes) > 0 && d(p.frames) == 0;
    const auto n = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
    const std::uint64_t nmea = d(p.nmea), vn_ascii = d(p.nmea, 1), rtcm3 = d(p.nmea, 2);
    std::string why, state;
    if (d(p.foreign_frames) > 0) {
      why = sprintf_text("%s: %llu %s frames (and no %s frame) in %.0f s from %s: gnss.device and imu.device swapped?",
                         p.name, n(d(p.foreign_frames)), p.other, p.protocol, window, dev);
      state = sprintf_text("%s: %s frames, no %s, from %s", p.title, p.other, p.protocol, dev);
    } else if (k == 0 && nmea > 0) {
      why = sprintf_text(
          "gnss: NMEA text, no UBX: %llu NMEA sentences and no UBX frame in %.0f s from %s: enable UBX "
          "output (UBX-NAV-PVT) on this port, or set gnss.configure: true",
          n(nmea), window, dev);
      state = sprintf_text("GNSS: NMEA text, no UBX, from %s", dev);
    } else if (k == 1 && vn_ascii > 0) {
      why = sprintf_text(
          "imu: VN-100 ASCII output, no binary: %llu $VN sentences and no binary frame in %.0f s from "
          "%s: enable binary output (register 75) on this port, or set imu.configure: true",
          n(vn_ascii), window, dev);
      state = sprintf_text("IMU: VN-100 ASCII output, no binary, from %s", dev);
    } else if (rtcm3 > 0) {
      why = sprintf_text(
          "%s: RTCM3 corrections, no %s: %llu RTCM3 frames and no %s frame in %.0f s from %s: a "
          "corrections stream (a base station's or an NTRIP client's output), not the %s's output port",
          p.name, p.protocol, n(rtcm3), p.protocol, window, dev, k == 0 ? "receiver" : "IMU");
      state = sprintf_text("%s: RTCM3 corrections, no %s, from %s", p.title, p.protocol, dev);
    } else if (nmea + vn_ascii > 0) {
      why = sprintf_text("%s: %s text (%llu sentences) and no %s frame in %.0f s from %s: %s", p.name,
                         nmea > 0 ? "NMEA" : "VN-100 ASCII", n(nmea + vn_ascii), p.protocol, window, dev,
                         nmea > 0 ? "a GNSS receiver on imu.device?" : "gnss.device and imu.device swapped?");
      state = sprintf_text("%s: %s text, no %s, from %s", p.title, nmea > 0 ? "NMEA" : "VN-100 ASCII", p.protocol, dev);
    } else {
      why = sprintf_text(
          "%s: %llu bytes in %.0f s from %s at %d baud but no %s frame, and no NMEA, VN-100 ASCII or "
          "RTCM3 either: wrong baud rate? (%s.baud)",
          p.name, n(d(p.bytes)), window, dev, p.device->baud, p.protocol, p.name);
      state = sprintf_text("%s: bytes but no %s frame from %s (wrong baud rate?)", p.title, p.protocol, dev);
    }
    set(garbage_faults[k], garbage, why, sprintf_text("%s: %s frames arriving", p.name, p.protocol), out);
    if (active_[garbage_faults[k]]) {
      serial_state_[k] = state;
    } else if (closed) {
      serial_state_[k] = sprintf_text("%s: cannot open %s; waiting for it", p.title, dev);
    }
  }
  set(kGnssNoPvt, gnss_used && judged(s) && delta(s, C::kGnssFrames) > 0 && delta(s, C::kPoseFixes) == 0,
      sprintf_text("gnss: %llu UBX frames in %.0f s but no NAV-PVT: enable UBX-NAV-PVT output on this port (%s)",
                   static_cast<unsigned long long>(delta(s, C::kGnssFrames)), window, config_.gnss.device.c_str()),
      "gnss: NAV-PVT arriving", out);
  if (active_[kGnssNoPvt]) serial_state_[0] = "GNSS: UBX frames but no NAV-PVT from " + config_.gnss.device;
  set(kImuNoAttitude,
      imu_used && judged(s) && delta(s, C::kPoseImuWithoutAttitude) > 0 && delta(s, C::kPoseAttitudes) == 0,
      sprintf_text("imu: %llu VN-100 frames in %.0f s carry no YawPitchRoll, Quaternion or DCM: add one to the "
                   "binary output (register 75)",
                   static_cast<unsigned long long>(delta(s, C::kPoseImuWithoutAttitude)), window),
      "imu: attitudes arriving", out);
  if (active_[kImuNoAttitude]) serial_state_[1] = "IMU: VN-100 frames without an attitude from " + config_.imu.device;
}

void HealthMonitor::localization(const StatusSnapshot& s, std::vector<HealthLine>& out) {
  if (config_.pose_source != PoseSource::kLcm) return;
  const char* channel = config_.lcm.pose_input.c_str();
  const double window = window_s(s);
  const std::uint64_t valid = delta(s, C::kPoseExternal), invalid = delta(s, C::kPoseExternalInvalid);
  const std::uint64_t malformed = delta(s, C::kPoseMessagesMalformed);
  set(kLocalizationSilent, live_ && judged(s) && valid + invalid + malformed == 0,
      sprintf_text("localization: no pose_input_t on %s for %.0f s: is the robot's localization running and "
                   "publishing there (lcm.channels.pose_input)? Sweeps are withheld until it returns",
                   channel, window),
      sprintf_text("localization: poses arriving on %s", channel), out);
  set(kLocalizationInvalid, invalid > 0,
      sprintf_text("localization: %llu of %llu poses in %.0f s on %s marked invalid (pose_input_t.valid false: the "
                   "localizer has lost itself); they are not used (pose.localization_invalid %llu)",
                   static_cast<unsigned long long>(invalid), static_cast<unsigned long long>(valid + invalid), window,
                   channel, static_cast<unsigned long long>(s[C::kPoseExternalInvalid])),
      sprintf_text("localization: no invalid poses on %s for %.0f s", channel, static_cast<double>(kWindow_ns) * 1e-9),
      out);
  set(kLocalizationMalformed, malformed > 0,
      sprintf_text("localization: %llu messages in %.0f s on %s are not pose_input_t (another type on this channel, "
                   "or cut short); dropped (pose.localization_malformed %llu)",
                   static_cast<unsigned long long>(malformed), window, channel,
                   static_cast<unsigned long long>(s[C::kPoseMessagesMalformed])),
      sprintf_text("localization: only pose_input_t on %s again", channel), out);
}

}  // namespace trajroi::daemon

namespace trajroi::daemon {

std::string pose_inputs_text(const StatusSnapshot& s, const DaemonConfig& config) {
  const std::string gnss = s.pose_age_s < 0.0 ? std::string("gnss no fix yet")
                                              : sprintf_text("gnss fix %u, h_acc %.2f m, age %.2f s",
                                                             unsigned{s.fix_type}, s.h_acc_m, s.pose_age_s);
  switch (config.pose_source) {
    case PoseSource::kGnssImu:
      return gnss + "; " +
             (s.attitude_age_s < 0.0 ? std::string("imu no attitude yet")
                                     : sprintf_text("imu attitude age %.2f s", s.attitude_age_s));
    case PoseSource::kGnss:
      return gnss + "; heading " + std::string(s.heading_source);
    case PoseSource::kLcm:
      return s.pose_age_s < 0.0 ? std::string("localization no pose yet")
                                : sprintf_text("localization pose age %.2f s", s.pose_age_s);
    case PoseSource::kFixed:
      break;
  }
  return "pose fixed (pose.fixed)";
}

}  // namespace trajroi::daemon
