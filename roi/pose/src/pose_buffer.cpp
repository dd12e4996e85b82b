#include "trajroi/pose/pose_buffer.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "trajroi/host/memory.hpp"

namespace trajroi::pose {

std::string_view to_string(RtkSolution s) noexcept {
  switch (s) {
    case RtkSolution::kNone:
      return "none";
    case RtkSolution::kFloat:
      return "float";
    case RtkSolution::kFixed:
      return "fixed";
  }
  return "unknown";
}

std::string_view to_string(PoseStatus status) noexcept {
  switch (status) {
    case PoseStatus::kValid:
      return "valid";
    case PoseStatus::kNoGnss:
      return "no GNSS fix yet";
    case PoseStatus::kNoAttitude:
      return "no attitude yet";
    case PoseStatus::kBeforeFirstSample:
      return "time precedes the oldest pose sample";
    case PoseStatus::kGnssTooOld:
      return "newest GNSS fix too old (beyond the extrapolation limit)";
    case PoseStatus::kAttitudeTooOld:
      return "newest attitude too old (beyond the extrapolation limit)";
    case PoseStatus::kGnssGap:
      return "gap between GNSS fixes too long";
    case PoseStatus::kAttitudeGap:
      return "gap between attitudes too long";
    case PoseStatus::kFixTypeTooLow:
      return "GNSS fix type below the gate";
    case PoseStatus::kNoGnssFixOk:
      return "GNSS fix not flagged gnssFixOK";
    case PoseStatus::kAccuracyTooLow:
      return "GNSS horizontal accuracy worse than the gate";
    case PoseStatus::kRtkTooLow:
      return "GNSS carrier solution worse than the gate";
  }
  return "unknown";
}

std::string describe(PoseStatus status, double measured, double limit, const PoseWords& words) {
  char text[200];
  const auto say = [&text](const char* pattern, auto... args) {
    std::snprintf(text, sizeof text, pattern, args...);
    return std::string(text);
  };
  const int fix = static_cast<int>(words.fix.size()), fixes = static_cast<int>(words.fixes.size());
  const int attitude = static_cast<int>(words.attitude.size()), attitudes = static_cast<int>(words.attitudes.size());
  switch (status) {
    case PoseStatus::kNoGnss:
      return say("no %.*s yet", fix, words.fix.data());
    case PoseStatus::kNoAttitude:
      return say("no %.*s yet", attitude, words.attitude.data());
    case PoseStatus::kFixTypeTooLow:
      return say("GNSS fix type %.0f < minimum %.0f (pose.min_fix_type)", measured, limit);
    case PoseStatus::kNoGnssFixOk:
      return "GNSS fix not flagged gnssFixOK (pose.require_gnss_fix_ok)";
    case PoseStatus::kRtkTooLow: {
      const auto word = [](double v) { return to_string(static_cast<RtkSolution>(static_cast<int>(v))); };
      const std::string_view got = word(measured), need = word(limit);
      return say("GNSS carrier solution %.*s, %.*s required (pose.require_rtk)", static_cast<int>(got.size()),
                 got.data(), static_cast<int>(need.size()), need.data());
    }
    case PoseStatus::kAccuracyTooLow:
      return say("GNSS horizontal accuracy %.2f m > limit %.2f m (pose.max_h_acc_m)", measured, limit);
    case PoseStatus::kGnssTooOld:
      return say("newest %.*s too old: %.3f s > %.3f s (pose.max_extrapolation_s)", fix, words.fix.data(), measured,
                 limit);
    case PoseStatus::kAttitudeTooOld:
      return say("newest %.*s too old: %.3f s > %.3f s (pose.max_extrapolation_s)", attitude, words.attitude.data(),
                 measured, limit);
    case PoseStatus::kGnssGap:
      return say("gap between %.*s %.3f s > %.3f s (pose.max_gap_s)", fixes, words.fixes.data(), measured, limit);
    case PoseStatus::kAttitudeGap:
      return say("gap between %.*s %.3f s > %.3f s (pose.max_gap_s)", attitudes, words.attitudes.data(), measured,
                 limit);
    default:
      return std::string(to_string(status));
  }
}

template <class T>
void PoseBuffer::Ring<T>::push(const T& item) noexcept {
  if (items.size() < capacity) {  // filling (head is 0): the items are written as they come
    items.push_back(item);
    ++size;
  } else {
    items[head] = item;
    head = (head + 1) % items.size();
  }
}

template <class T>
std::size_t PoseBuffer::Ring<T>::floor(std::int64_t t_ns) const noexcept {
  if (size == 0 || t_ns < at(0).t_ns) return size;
  constexpr std::size_t kNewestLooked = 8;
  std::size_t hi = size - 1;
  for (std::size_t n = 0; n < kNewestLooked && hi > 0; ++n, --hi) {
    if (at(hi).t_ns <= t_ns) return hi;
  }
  std::size_t lo = 0;  // invariant: at(lo).t_ns ≤ t
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo + 1) / 2;
    if (at(mid).t_ns <= t_ns) {
      lo = mid;
    } else {
      hi = mid - 1;
    }
  }
  return lo;
}

PoseBuffer::PoseBuffer(const PoseGate& gate, const Eigen::Vector3d& antenna_in_robot_m, std::size_t capacity)
    : gate_(gate), antenna_in_robot_m_(antenna_in_robot_m) {
  if (capacity < 2) throw std::invalid_argument("pose buffer: capacity must be at least 2 samples");
  if (gate.max_extrapolation_ns < 0 || gate.max_gap_ns <= 0 || !(gate.max_h_acc_m > 0)) {
    throw std::invalid_argument("pose gate: extrapolation must be ≥ 0, gap and accuracy bounds > 0");
  }
  if (!antenna_in_robot_m.allFinite()) throw std::invalid_argument("pose buffer: antenna lever arm is not finite");
  // Resident before they are written (one system call, not a page fault per page), and
  // written only as samples come (not value-initialised first: 1.3 MB at the default).
  fixes_.items.reserve(capacity);
  fixes_.capacity = capacity;
  host::populate(fixes_.items.data(), capacity * sizeof(StoredFix));
  attitudes_.items.reserve(capacity);
  attitudes_.capacity = capacity;
  host::populate(attitudes_.items.data(), capacity * sizeof(StoredAttitude));
}

bool PoseBuffer::add_fix(const GnssFix& fix) noexcept {
  if (!fix.antenna_global_m.allFinite() || std::isnan(fix.quality.h_acc_m)) {
    ++counters_.non_finite;
    return false;
  }
  if (fixes_.size > 0 && fix.t_ns <= fixes_.newest().t_ns) {
    ++counters_.out_of_order;
    return false;
  }
  StoredFix stored;
  static_cast<GnssFix&>(stored) = fix;
  if (fixes_.size > 0) {
    const GnssFix& prev = fixes_.newest();
    PoseQuery ignored;
    if (fix.t_ns - prev.t_ns <= gate_.max_gap_ns && check(prev.quality, ignored) == PoseStatus::kValid) {
      stored.extrapolates = true;
      stored.velocity = (fix.antenna_global_m - prev.antenna_global_m) / static_cast<double>(fix.t_ns - prev.t_ns);
    }
  }
  fixes_.push(stored);
  ++counters_.fixes;
  return true;
}

bool PoseBuffer::add_attitude(const AttitudeSample& a) noexcept {
  if (!a.global_from_robot.coeffs().allFinite() || a.global_from_robot.norm() < 1e-6) {
    ++counters_.non_finite;
    return false;
  }
  if (attitudes_.size > 0 && a.t_ns <= attitudes_.newest().t_ns) {
    ++counters_.out_of_order;
    return false;
  }
  StoredAttitude stored;
  stored.t_ns = a.t_ns;
  stored.global_from_robot = a.global_from_robot.normalized();
  stored.rotation = stored.global_from_robot.toRotationMatrix();
  stored.lever_arm_global_m = stored.global_from_robot * antenna_in_robot_m_;
  if (attitudes_.size > 0) {
    // As Eigen's slerp computes them (Quaternion.h), so that interpolating gives its results.
    const Eigen::Quaterniond& previous = attitudes_.newest().global_from_robot;
    SlerpPair& pair = stored.from_previous;
    pair.dot = previous.dot(stored.global_from_robot);
    const double abs_dot = std::abs(pair.dot);
    pair.linear = abs_dot >= 1.0 - std::numeric_limits<double>::epsilon();
    if (!pair.linear) {
      pair.theta = std::acos(abs_dot);
      pair.sin_theta = std::sin(pair.theta);
    }
  }
  attitudes_.push(stored);
  ++counters_.attitudes;
  return true;
}

PoseStatus PoseBuffer::check(const FixQuality& q, PoseQuery& out) const noexcept {
  const auto fail = [&out](PoseStatus s, double measured, double limit) {
    out.measured = measured;
    out.limit = limit;
    return s;
  };
  if (q.fix_type < gate_.min_fix_type || q.fix_type == 5) {  // 5: time only
    return fail(PoseStatus::kFixTypeTooLow, q.fix_type, gate_.min_fix_type);
  }
  if (gate_.require_gnss_fix_ok && !q.gnss_fix_ok) return PoseStatus::kNoGnssFixOk;
  if (!(q.h_acc_m <= gate_.max_h_acc_m)) return fail(PoseStatus::kAccuracyTooLow, q.h_acc_m, gate_.max_h_acc_m);
  if (q.rtk() < gate_.require_rtk) {
    return fail(PoseStatus::kRtkTooLow, static_cast<double>(q.rtk()), static_cast<double>(gate_.require_rtk));
  }
  return PoseStatus::kValid;
}

PoseQuery PoseBuffer::pose_at(std::int64_t t_ns) const noexcept {
  PoseQuery out;
  if (held_) {
    out.status = PoseStatus::kValid;
    out.global_from_robot = *held_;
    return out;
  }
  constexpr double kNsToS = 1e-9;
  const auto fail = [&out](PoseStatus s, std::int64_t measured_ns, std::int64_t limit_ns) {
    out.status = s;
    out.measured = static_cast<double>(measured_ns) * kNsToS;
    out.limit = static_cast<double>(limit_ns) * kNsToS;
    return out;
  };
  if (fixes_.size == 0) {
    out.status = PoseStatus::kNoGnss;
    return out;
  }
  if (attitudes_.size == 0) {
    out.status = PoseStatus::kNoAttitude;
    return out;
  }

  // Position of the antenna.
  Eigen::Vector3d antenna;
  const std::size_t f = fixes_.floor(t_ns);
  if (f == fixes_.size) {
    out.status = PoseStatus::kBeforeFirstSample;
    return out;
  }
  const StoredFix& a = fixes_.at(f);
  if (PoseStatus s = check(a.quality, out); s != PoseStatus::kValid) {
    out.status = s;
    return out;
  }
  if (f + 1 < fixes_.size) {
    const GnssFix& b = fixes_.at(f + 1);
    if (b.t_ns - a.t_ns > gate_.max_gap_ns) return fail(PoseStatus::kGnssGap, b.t_ns - a.t_ns, gate_.max_gap_ns);
    if (PoseStatus s = check(b.quality, out); s != PoseStatus::kValid) {
      out.status = s;
      return out;
    }
    const double w = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
    antenna = a.antenna_global_m + w * (b.antenna_global_m - a.antenna_global_m);
  } else {
    const std::int64_t ahead = t_ns - a.t_ns;
    if (ahead > gate_.max_extrapolation_ns) return fail(PoseStatus::kGnssTooOld, ahead, gate_.max_extrapolation_ns);
    antenna = a.antenna_global_m;
    // Linear extrapolation from the last two fixes when they are close enough and both pass
    // (the previous one still held: its velocity was taken as this one arrived).
    if (f > 0 && ahead > 0 && a.extrapolates) antenna += a.velocity * static_cast<double>(ahead);
  }

  // Attitude.
  const std::size_t r = attitudes_.floor(t_ns);
  if (r == attitudes_.size) {
    out.status = PoseStatus::kBeforeFirstSample;
    return out;
  }
  const StoredAttitude& qa = attitudes_.at(r);
  out.global_from_robot = Eigen::Isometry3d::Identity();
  if (r + 1 < attitudes_.size) {
    const StoredAttitude& qb = attitudes_.at(r + 1);
    if (qb.t_ns - qa.t_ns > gate_.max_gap_ns) {
      return fail(PoseStatus::kAttitudeGap, qb.t_ns - qa.t_ns, gate_.max_gap_ns);
    }
    const double w = static_cast<double>(t_ns - qa.t_ns) / static_cast<double>(qb.t_ns - qa.t_ns);
    // qa.slerp(w, qb) with the pair's part taken from qb.
    const SlerpPair& pair = qb.from_previous;
    double scale0 = 1.0 - w;
    double scale1 = w;
    if (!pair.linear) {
      scale0 = std::sin((1.0 - w) * pair.theta) / pair.sin_theta;
      scale1 = std::sin(w * pair.theta) / pair.sin_theta;
    }
    if (pair.dot < 0.0) scale1 = -scale1;
    const Eigen::Quaterniond attitude(scale0 * qa.global_from_robot.coeffs() + scale1 * qb.global_from_robot.coeffs());
    out.global_from_robot.linear() = attitude.toRotationMatrix();
    out.global_from_robot.translation() = antenna - attitude * antenna_in_robot_m_;
  } else {
    if (t_ns - qa.t_ns > gate_.max_extrapolation_ns) {
      return fail(PoseStatus::kAttitudeTooOld, t_ns - qa.t_ns, gate_.max_extrapolation_ns);
    }
    // Held within the bound: what the attitude alone gives was computed as it arrived.
    out.global_from_robot.linear() = qa.rotation;
    out.global_from_robot.translation() = antenna - qa.lever_arm_global_m;
  }
  out.status = PoseStatus::kValid;
  return out;
}

}  // namespace trajroi::pose
