#include "trajroi/vlp16/stream_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace trajroi::vlp16 {

void DecodedPacket::assign(std::span<const Point> decoded_points, const PacketDecoder::Result& decode_result) noexcept {
  count = static_cast<std::uint32_t>(std::min(decoded_points.size(), points.size()));
  std::copy_n(decoded_points.begin(), count, points.begin());
  result = decode_result;
}

namespace {

constexpr double kLossFactor = 1.5;  // a step beyond 1.5 expected ones means packets are missing
// Points reserved for a frame: a dual-return sweep at 5 Hz is about 300 packets of up to 384.
constexpr std::size_t kFrameReserve = 300 * kPointsPerPacket;

// Packets missing in a step of `observed` where `expected` was due, at least one.
std::uint32_t missing(double observed, double expected) noexcept {
  const double n = std::round(observed / expected) - 1.0;
  return n < 1.0 ? 1u : n > 1e9 ? 1'000'000'000u : static_cast<std::uint32_t>(n);
}

// Any azimuth in degrees as [0, 360), exactly the same value when already there (a negative
// one just below 0 gives 0, not 360).
double wrapped_deg(double deg) noexcept {
  double r = std::fmod(deg, 360.0);
  if (r < 0.0) r += 360.0;
  return r >= 360.0 ? 0.0 : r;
}

// A point's azimuth past the cut, [0, 360) (the frame's order).
inline double phase_deg(float azimuth_deg, double cut_deg) noexcept {
  double phase = static_cast<double>(azimuth_deg) - cut_deg;
  if (phase < 0.0) phase += 360.0;
  return phase;
}

// A packet's points [0, count) placed on the frame in one pass, when none of them can end it:
// all on one side of the cut, within half a turn of one another and of the point before them
// (`last_phase_deg`), and within kMaxFrameDuration_ns of the frame's start. The point-by-point
// loop in accept() would then neither break nor do anything else than this: the same time
// offsets, end time and last phase, to the bit. `bounds`: the decode's azimuth and time offset
// bounds, which hold every point's. Answers false, having written nothing, for a packet that
// may end the frame (about one per sweep), which then takes that loop.
bool place_whole_packet(Point* p, std::size_t count, const PacketDecoder::Result& bounds, std::int64_t time_ns,
                        std::int64_t start_ns, double cut_deg, double& last_phase_deg,
                        std::int64_t& end_time_ns) noexcept {
  if (count == 0) return false;
  const float az_min = bounds.azimuth_min_deg;
  const float az_max = bounds.azimuth_max_deg;
  // On one side of the cut the phase grows with the azimuth (each step rounds monotonically),
  // so the bounds' phases bound the points'.
  if ((static_cast<double>(az_min) - cut_deg < 0.0) != (static_cast<double>(az_max) - cut_deg < 0.0)) return false;
  const double phase_min = phase_deg(az_min, cut_deg);
  const double phase_max = phase_deg(az_max, cut_deg);
  if (phase_min < phase_max - 180.0 || phase_min < last_phase_deg - 180.0) return false;
  if (time_ns + bounds.time_offset_max_ns - start_ns > kMaxFrameDuration_ns) return false;
  std::uint32_t offset_max = 0;
  for (std::size_t k = 0; k < count; ++k) {
    offset_max = std::max(offset_max, p[k].time_offset_ns);
    p[k].time_offset_ns = static_cast<std::uint32_t>(time_ns + p[k].time_offset_ns - start_ns);
  }
  end_time_ns = std::max(end_time_ns, time_ns + offset_max);
  last_phase_deg = phase_deg(p[count - 1].azimuth_deg, cut_deg);
  return true;
}
}  // namespace

std::uint16_t cut_centidegrees(double cut_azimuth_deg) noexcept {
  if (!std::isfinite(cut_azimuth_deg)) return 0;
  return static_cast<std::uint16_t>(static_cast<std::uint32_t>(std::lround(wrapped_deg(cut_azimuth_deg) * 100.0)) %
                                    kAzimuthLimit);
}

bool may_complete_frame(std::span<const std::uint8_t> packet, std::uint16_t cut_cdeg) noexcept {
  if (packet.size() < kDataPacketBytes) return false;
  const auto first = static_cast<std::uint16_t>(block_azimuth(packet, 0) % kAzimuthLimit);
  const auto last = static_cast<std::uint16_t>(block_azimuth(packet, kBlocks - 1) % kAzimuthLimit);
  return azimuth_gap(first, cut_cdeg) <= azimuth_gap(first, last) + kFrameEndMargin_cdeg ||
         azimuth_gap(cut_cdeg, first) <= kFrameEndMargin_cdeg;
}

StreamDecoder::StreamDecoder(const Calibration& calibration, StreamOptions options)
    : options_(options), model_(options.detect_model ? std::nullopt : std::optional<Model>(options.model)) {
  for (std::size_t m = 0; m < kModelCount; ++m) {
    const auto model = static_cast<Model>(m);
    if (model == options.model) {
      decoders_[m] = std::make_unique<PacketDecoder>(calibration, options.decode, model);
    } else if (options.detect_model) {
      decoders_[m] = std::make_unique<PacketDecoder>(Calibration::for_model(model), options.decode, model);
    }
  }
  current_ = decoders_[static_cast<std::size_t>(options.model)].get();
  options_.cut_azimuth_deg = wrapped_deg(options_.cut_azimuth_deg);
  held_.reserve(ModelCheck::kMaxUndecided);
  frame_.points.reserve(kFrameReserve);
  carried_.reserve(kPointsPerPacket);
}

std::int64_t StreamDecoder::packet_time_ns(std::uint32_t toh_us, std::int64_t receive_time_ns, double period_us) {
  // The packet leaves the sensor after its last firing: its first one was a period earlier.
  const std::int64_t by_receive = receive_time_ns - std::llround(period_us * 1000.0);
  if (have_last_) {
    unwrapped_toh_us_ += toh_delta_us(last_toh_us_, toh_us);
    const std::int64_t by_sensor = anchor_time_ns_ + unwrapped_toh_us_ * 1000;
    if (std::llabs(by_sensor - by_receive) <= kClockResetThreshold_ns) {
      latency_min_ns_ = std::min(latency_min_ns_, by_receive - by_sensor);
      return by_sensor;
    }
    ++counters_.clock_resets;
  }
  anchor_time_ns_ = by_receive;
  unwrapped_toh_us_ = 0;
  latency_min_ns_ = kNoLatency;
  window_start_ns_ = receive_time_ns;
  return by_receive;
}

std::int64_t StreamDecoder::settle_anchor(std::int64_t receive_time_ns) noexcept {
  std::int64_t shift = 0;
  if (latency_min_ns_ < 0) {
    shift = latency_min_ns_;  // a packet came earlier than the anchor foretold
  } else if (receive_time_ns - window_start_ns_ >= kClockWindow_ns) {
    shift = latency_min_ns_ == kNoLatency ? 0 : latency_min_ns_;  // every one came later
  } else {
    return 0;
  }
  anchor_time_ns_ += shift;
  latency_min_ns_ = kNoLatency;
  window_start_ns_ = receive_time_ns;
  return shift;
}

void StreamDecoder::accept(std::span<const std::uint8_t> packet, std::int64_t receive_time_ns, FrameSink& sink,
                           const DecodedPacket* decoded) {
  const auto mode = static_cast<ReturnMode>(return_mode_byte(packet));
  const bool dual = mode == ReturnMode::kDual;
  const std::size_t step = dual ? 2 : 1;
  const double block_us = spec(current_->model()).block_duration_us();
  const double period_us = static_cast<double>(kBlocks / step) * block_us;
  const std::uint32_t toh = timestamp_us(packet);
  const std::uint16_t first_azimuth = block_azimuth(packet, 0);

  std::uint32_t lost = 0;
  std::int64_t delta_us = 0;
  if (have_last_ && toh_delta_us(last_toh_us_, toh) < -kRestartThreshold_us) {
    // The sensor's clock started again: a new stream, whose first frame is partial.
    ++counters_.restarts;
    finish_frame(sink, true);
    first_frame_ = true;
    have_last_ = false;
    have_phase_ = false;
    cut_foreseen_ = false;
    rate_cdeg_per_us_ = 0.0;
  }
  if (have_last_) {
    delta_us = toh_delta_us(last_toh_us_, toh);
    if (delta_us == 0) {
      ++counters_.duplicates;
      return;
    }
    if (delta_us < 0) {
      ++counters_.out_of_order;
      // It was counted lost when the packet after it came first.
      if (frame_.lost_packets > 0) {
        --frame_.lost_packets;
        --counters_.lost_packets;
      }
      append_late(packet, anchor_time_ns_ + (unwrapped_toh_us_ + delta_us) * 1000, sink, decoded);
      return;
    }
    const auto delta = static_cast<double>(delta_us);
    const double host_elapsed_us = static_cast<double>(receive_time_ns - last_receive_ns_) / 1000.0;
    if (delta > 2.0 * host_elapsed_us + static_cast<double>(kClockResetThreshold_ns) / 1000.0) {
      ++counters_.clock_jumps;
      if (host_elapsed_us > kLossFactor * period_us) lost = missing(host_elapsed_us, period_us);
    } else if (delta > kLossFactor * period_us) {
      lost = missing(delta, period_us);
    } else if (rate_cdeg_per_us_ > 0.0) {
      const double expected_cdeg = rate_cdeg_per_us_ * delta;
      const auto observed_cdeg = static_cast<double>(azimuth_gap(last_first_azimuth_, first_azimuth));
      if (observed_cdeg > kLossFactor * expected_cdeg) lost = missing(observed_cdeg, expected_cdeg);
    }
  }
  std::int64_t time_ns = packet_time_ns(toh, receive_time_ns, period_us);
  const std::optional<std::int64_t> utc_ns = utc_clock_.to_utc_ns(toh);

  if (lost > 0) {
    counters_.lost_packets += lost;
    // Packets lost across the cut azimuth take the cut with them: close the frame here,
    // giving it the lost packets whose first firing was still before the cut.
    const double per_packet_deg = rate_cdeg_per_us_ * period_us / 100.0;
    double last_start_phase = static_cast<double>(last_first_azimuth_) / 100.0 - options_.cut_azimuth_deg;
    if (last_start_phase < 0.0) last_start_phase += 360.0;
    const double lost_span_deg = per_packet_deg * static_cast<double>(lost);
    if (have_phase_ && per_packet_deg > 0.0 && last_start_phase + lost_span_deg + per_packet_deg >= 360.0) {
      const double before = std::ceil((360.0 - last_start_phase) / per_packet_deg - 1e-6) - 1.0;
      const auto lost_before = static_cast<std::uint32_t>(std::clamp(before, 0.0, static_cast<double>(lost)));
      frame_.lost_packets += lost_before;
      finish_frame(sink, false);
      have_phase_ = false;
      cut_foreseen_ = false;
      frame_.lost_packets += lost - lost_before;
    } else {
      frame_.lost_packets += lost;
    }
  }
  have_last_ = true;
  last_toh_us_ = toh;
  last_receive_ns_ = receive_time_ns;
  last_first_azimuth_ = first_azimuth;
  const std::size_t last_firing_block = kBlocks - step;
  const auto last_firing_azimuth = static_cast<std::uint16_t>(block_azimuth(packet, last_firing_block) % kAzimuthLimit);
  const std::uint32_t span_cdeg = azimuth_gap(first_azimuth, last_firing_azimuth);
  rate_cdeg_per_us_ = static_cast<double>(span_cdeg) / (static_cast<double>(kBlocks / step - 1) * block_us);

  product_id_ = vlp16::product_id(packet);
  return_mode_ = mode;

  // The points are decoded straight onto the frame and then placed there (time after the
  // frame's start); where the azimuth passes the cut, the rest of the packet moves to the next
  // frame. The loop keeps its state in locals, written back around the rare end of a frame.
  std::vector<Point>& points = frame_.points;
  std::size_t i = points.size();
  const PacketDecoder::Result decoded_bounds = decode_onto_frame(packet, decoded);
  std::int64_t end_time_ns = frame_.end_time_ns;
  double last_phase_deg = last_phase_deg_;
  bool have_phase = have_phase_;
  bool counted = false;
  while (i < points.size()) {
    // Most points neither begin a frame nor cross the cut or the longest frame: those are
    // placed here with the frame's fields in locals; the point that ends this loop early
    // goes through the general step below (the same arithmetic, so the same result).
    if (i > 0 && have_phase) {
      Point* const p = points.data();
      const std::size_t n = points.size();
      const std::int64_t start_ns = frame_.start_time_ns;
      const double cut_deg = options_.cut_azimuth_deg;
      const std::size_t from = i;
      if (place_whole_packet(p + i, n - i, decoded_bounds, time_ns, start_ns, cut_deg, last_phase_deg, end_time_ns))
        i = n;
      for (; i < n; ++i) {
        const double phase = phase_deg(p[i].azimuth_deg, cut_deg);
        const std::int64_t t = time_ns + p[i].time_offset_ns;
        if (phase < last_phase_deg - 180.0 || t - start_ns > kMaxFrameDuration_ns) break;
        last_phase_deg = phase;
        p[i].time_offset_ns = static_cast<std::uint32_t>(t - start_ns);
        end_time_ns = std::max(end_time_ns, t);
      }
      if (i > from && !counted) {
        ++frame_.packets;
        counted = true;
      }
      if (i == n) break;
    }
    const double phase = phase_deg(points[i].azimuth_deg, options_.cut_azimuth_deg);
    std::int64_t t = time_ns + points[i].time_offset_ns;
    // After a foreseen end the frame is closed already: the wrap past the cut is no new one,
    // and firings still before the cut (the motor slower than foreseen) begin the next frame.
    const bool cut = have_phase && phase < last_phase_deg - 180.0 && !cut_foreseen_;
    if (phase < 180.0) cut_foreseen_ = false;
    if (cut || (i > 0 && t - frame_.start_time_ns > kMaxFrameDuration_ns)) {
      carried_.assign(points.begin() + static_cast<std::ptrdiff_t>(i), points.end());
      points.resize(i);
      frame_.end_time_ns = end_time_ns;
      finish_frame(sink, !cut);
      points.assign(carried_.begin(), carried_.end());
      i = 0;
    }
    last_phase_deg = phase;
    have_phase = true;
    Point& point = points[i];
    if (i == 0) {
      const std::int64_t shift = settle_anchor(receive_time_ns);
      time_ns += shift;
      t += shift;
      frame_.start_time_ns = t;
      end_time_ns = t;
      frame_.start_utc_ns = utc_ns ? std::optional(*utc_ns + point.time_offset_ns) : std::nullopt;
      frame_.return_mode = mode;
    }
    if (!counted) {
      ++frame_.packets;
      counted = true;
    }
    point.time_offset_ns = static_cast<std::uint32_t>(t - frame_.start_time_ns);
    end_time_ns = std::max(end_time_ns, t);
    ++i;
  }
  frame_.end_time_ns = end_time_ns;
  last_phase_deg_ = last_phase_deg;
  have_phase_ = have_phase;
  if (!counted) ++frame_.packets;
  report_points(sink);
  // The cut between this packet and the next: the frame is whole now, not a packet later.
  if (next_packet_past_cut(last_firing_azimuth, rate_cdeg_per_us_ * block_us)) {
    finish_frame(sink, false);
    cut_foreseen_ = true;
  }
}

bool StreamDecoder::next_packet_past_cut(std::uint16_t last_azimuth_cdeg, double step_cdeg) const noexcept {
  if (!have_phase_ || frame_.points.empty() || !(step_cdeg > 0.0) || step_cdeg > kMaxForeseenStep_cdeg) return false;
  // The next packet's first firing, a block step on, less the margin: its every point is at or
  // past that azimuth (a firing's points are at or after its block's azimuth).
  const double next_cdeg = static_cast<double>(last_azimuth_cdeg) + step_cdeg - kForesightMargin_cdeg;
  const double next_phase = phase_deg(static_cast<float>(wrapped_deg(next_cdeg / 100.0)), options_.cut_azimuth_deg);
  return next_phase < last_phase_deg_ - 180.0;
}

PacketDecoder::Result StreamDecoder::decode_onto_frame(std::span<const std::uint8_t> packet,
                                                       const DecodedPacket* decoded) {
  std::vector<Point>& points = frame_.points;
  PacketDecoder::Result r;
  if (decoded != nullptr) {
    reserve_packet_room(points);  // as decode() grows it
    const std::span<const Point> ahead = decoded->decoded();
    points.insert(points.end(), ahead.begin(), ahead.end());
    r = decoded->result;
    ++counters_.decoded_ahead;
  } else {
    r = current_->decode(packet, points);
  }
  ++counters_.decoded_packets;
  counters_.points += r.points;
  counters_.no_return += r.no_return;
  counters_.out_of_range += r.out_of_range;
  counters_.merged_returns += r.merged_returns;
  return r;
}

void StreamDecoder::report_points(FrameSink& sink) {
  if (frame_.points.size() > reported_) {
    const std::size_t first = reported_;
    reported_ = frame_.points.size();
    sink.on_points(frame_, first);
  }
}

void StreamDecoder::append_late(std::span<const std::uint8_t> packet, std::int64_t packet_time_ns, FrameSink& sink,
                                const DecodedPacket* decoded) {
  if (frame_.points.empty() || packet_time_ns < frame_.start_time_ns) {
    ++counters_.late_dropped;
    return;
  }
  const std::size_t first = frame_.points.size();
  (void)decode_onto_frame(packet, decoded);
  ++frame_.packets;
  for (std::size_t i = first; i < frame_.points.size(); ++i) {
    Point& point = frame_.points[i];
    const std::int64_t t = packet_time_ns + point.time_offset_ns;
    point.time_offset_ns = static_cast<std::uint32_t>(t - frame_.start_time_ns);
    frame_.end_time_ns = std::max(frame_.end_time_ns, t);
  }
  report_points(sink);
}

void StreamDecoder::finish_frame(FrameSink& sink, bool partial) {
  report_points(sink);
  reported_ = 0;
  if (!frame_.points.empty() || frame_.packets > 0) {
    frame_.index = next_index_++;
    frame_.partial = partial || first_frame_;
    ++(frame_.partial ? counters_.partial_frames : counters_.frames);
    sink.on_frame(frame_);
    first_frame_ = false;
  }
  frame_.points.clear();
  frame_.packets = 0;
  frame_.lost_packets = 0;
  frame_.start_time_ns = 0;
  frame_.end_time_ns = 0;
  frame_.start_utc_ns.reset();
}

void StreamDecoder::flush(FrameSink& sink) {
  // 0x21 packets still waiting for a verdict never showed a VLP-16's timing.
  counters_.rejected[static_cast<std::size_t>(PacketError::kUnsupportedProduct)] += held_.size();
  held_.clear();
  finish_frame(sink, true);
  have_phase_ = false;
  cut_foreseen_ = false;
}

}  // namespace trajroi::vlp16
