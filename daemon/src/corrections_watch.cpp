#include "corrections_watch.hpp"

#include <cmath>
#include <limits>

#include "corrections_link.hpp"
#include "health_format.hpp"

namespace trajroi::daemon {

CorrectionsWatch::CorrectionsWatch(const DaemonConfig& config, const CorrectionsLink* link, bool live)
    : config_(config), link_(link), live_(live) {}

CorrectionsFigures CorrectionsWatch::update(const StatusSnapshot& s, std::int64_t now_ns, const AddCounter& add,
                                            std::vector<HealthLine>& lines) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The carrier solution's changes (from the first NAV-PVT on).
  if (s.rtk >= 0 && s.rtk != rtk_) {
    const auto solution = static_cast<pose::RtkSolution>(s.rtk);
    if (solution == pose::RtkSolution::kFixed) {
      lines.push_back({HealthLine::Level::kInfo, sprintf_text("RTK fixed (h_acc %.3f m)", s.h_acc_m)});
    } else if (solution == pose::RtkSolution::kFloat) {
      lines.push_back({HealthLine::Level::kInfo, sprintf_text("RTK float (h_acc %.3f m)", s.h_acc_m)});
    } else if (rtk_ > 0) {
      lines.push_back(
          {HealthLine::Level::kWarning, sprintf_text("RTK lost: standalone fix (h_acc %.2f m)%s", s.h_acc_m,
                                                     link_ != nullptr ? "; see the corrections' state" : "")});
    }
    rtk_ = s.rtk;
  }
  CorrectionsFigures f{std::string(), nan, nan};
  if (link_ == nullptr) return f;
  if (started_ns_ == 0) started_ns_ = now_ns;
  const CorrectionsStats c = link_->stats();
  const std::int64_t written_ns = link_->last_written_ns.load(std::memory_order_relaxed);
  f.text = c.state;
  f.age_s = written_ns > 0 ? static_cast<double>(now_ns - written_ns) * 1e-9 : nan;
  if (bytes_at_ns_ > 0 && now_ns > bytes_at_ns_)
    f.bytes_per_s = static_cast<double>(c.in.bytes - bytes_) / (static_cast<double>(now_ns - bytes_at_ns_) * 1e-9);
  bytes_ = c.in.bytes;
  bytes_at_ns_ = now_ns;

  // Too old: none written for longer than the limit (since the start, before the first one).
  const double limit = config_.gnss_corrections.max_age_s;
  const double since_s = written_ns > 0 ? f.age_s : static_cast<double>(now_ns - started_ns_) * 1e-9;
  const bool old = live_ && since_s > limit;
  if (old && !old_) {
    lines.push_back({HealthLine::Level::kWarning,
                     sprintf_text("corrections lost for %.1f s (none written into the receiver; more than "
                                  "gnss.max_correction_age_s %.1f s): %s",
                                  since_s, limit, c.state.c_str())});
  } else if (!old && old_) {
    lines.push_back({HealthLine::Level::kInfo,
                     sprintf_text("corrections flowing again (age %.1f s): %s", f.age_s, c.state.c_str())});
  }
  old_ = old;
  not_rtcm3(c, now_ns, lines);

  add("corrections.bytes", c.in.bytes);
  add("corrections.frames", c.in.frames);
  add("corrections.crc_errors", c.in.crc_errors);
  add("corrections.not_rtcm3_bytes", c.in.other_bytes);
  add("corrections.connects", c.in.connects);
  add("corrections.disconnects", c.in.disconnects);
  add("corrections.refusals", c.in.refusals);
  add("corrections.gga_sent", c.in.gga_sent);
  add("corrections.ring_drops", c.ring_drops);
  add("corrections.written_frames", link_->written_frames.load(std::memory_order_relaxed));
  add("corrections.written_bytes", link_->written_bytes.load(std::memory_order_relaxed));
  add("corrections.write_failures", link_->write_failures.load(std::memory_order_relaxed));
  add("corrections.port_closed_drops", link_->not_written.load(std::memory_order_relaxed));
  for (const auto& [number, count] : c.in.by_message)
    add("corrections.rtcm." + std::to_string(number), count);
  return f;
}

// Bytes that never make a frame (not RTCM3: RTCM2, CMR, a receiver's own output, a wrong baud
// rate) and frames that fail their CRC (line noise on a radio): counted, and named here.
void CorrectionsWatch::not_rtcm3(const CorrectionsStats& c, std::int64_t now_ns, std::vector<HealthLine>& lines) {
  const std::uint64_t new_frames = c.in.frames - frames_;
  const std::uint64_t new_other = c.in.other_bytes - other_bytes_;
  frames_ = c.in.frames;
  other_bytes_ = c.in.other_bytes;
  if (new_frames > 0) {
    frameless_s_ = 0;
    frameless_bytes_ = 0;
  } else if (new_other > 0) {
    ++frameless_s_;
    frameless_bytes_ += new_other;
  }
  if (frameless_s_ >= 3 && !frameless_said_) {
    lines.push_back({HealthLine::Level::kWarning,
                     sprintf_text("corrections: %llu bytes and no RTCM3 frame in %d s (%s): is the source's output "
                                  "RTCM 3 (not RTCM 2, CMR or a receiver's own messages), and its baud rate right? "
                                  "(corrections.not_rtcm3_bytes %llu)",
                                  static_cast<unsigned long long>(frameless_bytes_), frameless_s_, c.state.c_str(),
                                  static_cast<unsigned long long>(c.in.other_bytes))});
    frameless_said_ = true;
  } else if (new_frames > 0 && frameless_said_) {
    lines.push_back(
        {HealthLine::Level::kInfo, sprintf_text("corrections: RTCM3 frames arriving (%s)", c.state.c_str())});
    frameless_said_ = false;
  }
  constexpr std::int64_t kMinute_ns = 60'000'000'000;
  if (c.in.crc_errors > crc_said_ && (crc_said_ns_ == 0 || now_ns - crc_said_ns_ >= kMinute_ns)) {
    lines.push_back({HealthLine::Level::kWarning,
                     sprintf_text("corrections: %llu RTCM3 frames failed their CRC-24Q since %s (line noise on the "
                                  "link?): not written into the receiver (corrections.crc_errors %llu)",
                                  static_cast<unsigned long long>(c.in.crc_errors - crc_said_),
                                  crc_said_ns_ == 0 ? "the start" : "the last such line",
                                  static_cast<unsigned long long>(c.in.crc_errors))});
    crc_said_ = c.in.crc_errors;
    crc_said_ns_ = now_ns;
  }
}

}  // namespace trajroi::daemon
