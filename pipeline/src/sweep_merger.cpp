#include "trajroi/pipeline/sweep_merger.hpp"

#include <algorithm>
#include <cstring>

#include "columns.hpp"

namespace trajroi::pipeline {
namespace {

// The first `n` elements of `from` after those of `to`, in one copy.
template <typename Array>
void append_array(Array& to, const Array& from, std::size_t n) {
  if (n != 0) std::memcpy(grown(to, n), from.data(), n * sizeof(from[0]));
}

// The columns of `from` after those of `to`, as far as `capacity` allows, their time offsets
// moved by `shift_ns` (they count from the merged sweep's start); the count appended.
std::size_t append_columns(PointColumns& to, const PointColumns& from, std::size_t capacity, std::int32_t shift_ns) {
  const std::size_t n = std::min(from.size(), capacity - std::min(capacity, to.size()));
  append_array(to.x, from.x, n);
  append_array(to.y, from.y, n);
  append_array(to.z, from.z, n);
  append_array(to.intensity, from.intensity, n);
  append_array(to.ring, from.ring, n);
  append_array(to.return_type, from.return_type, n);
  std::int32_t* const t = grown(to.time_offset_ns, n);
  const std::int32_t* const f = from.time_offset_ns.data();
  for (std::size_t k = 0; k < n; ++k)
    t[k] = f[k] + shift_ns;
  return n;
}

}  // namespace

SweepMerger::SweepMerger(std::size_t sensors, std::size_t points_per_sweep, std::size_t centres, std::size_t raw_points,
                         MergeOptions options)
    : options_(options), capacity_((options.per_sensor ? 1 : sensors) * points_per_sweep), last_ns_(sensors, 0) {
  merged_.reserve(capacity_, centres, (options.per_sensor ? 1 : sensors) * raw_points);
}

bool SweepMerger::silent(std::size_t sensor, std::int64_t now_ns) const noexcept {
  const std::int64_t since = last_ns_[sensor] != 0 ? last_ns_[sensor] : first_input_ns_;
  return since != 0 && now_ns - since > options_.silent_ns;
}

void SweepMerger::add(std::size_t sensor, const Sweep& sweep, std::int64_t now_ns, SweepSink& sink) {
  if (first_input_ns_ == 0) first_input_ns_ = now_ns;
  now_ns_ = now_ns;
  const auto bit = static_cast<std::uint32_t>(1U << sensor);
  if (options_.per_sensor) {
    last_ns_[sensor] = now_ns;
    open_ = true;
    waited_for_ = bit;
    append(sensor, sweep);
    emit(sink);
    return;
  }
  // A second sweep of one sensor: the window closes without waiting longer for the others.
  if (open_ && (merged_.sensors & bit) != 0) emit(sink);
  if (!open_) {
    open_ = true;
    deadline_ns_ = now_ns + options_.max_wait_ns;
    waited_for_ = 0;
    for (std::size_t i = 0; i < last_ns_.size(); ++i) {
      if (i == sensor || !silent(i, now_ns)) waited_for_ |= 1U << i;
    }
  }
  last_ns_[sensor] = now_ns;
  waited_for_ |= bit;  // one silent until now counts again
  append(sensor, sweep);
  if ((merged_.sensors & waited_for_) == waited_for_) emit(sink);
}

void SweepMerger::tick(std::int64_t now_ns, SweepSink& sink) {
  if (first_input_ns_ == 0) first_input_ns_ = now_ns;
  now_ns_ = now_ns;
  if (!open_) return;
  // A sensor that fell silent while the window was open is not waited for any longer either.
  for (std::size_t i = 0; i < last_ns_.size(); ++i) {
    if ((merged_.sensors & (1U << i)) == 0 && silent(i, now_ns)) waited_for_ &= ~(1U << i);
  }
  if (now_ns > deadline_ns_ || (merged_.sensors & waited_for_) == waited_for_) emit(sink);
}

void SweepMerger::flush(SweepSink& sink) {
  if (open_) emit(sink);
}

void SweepMerger::append(std::size_t sensor, const Sweep& sweep) {
  Sweep& m = merged_;
  // The header: the first sensor's, or the first whose pose was valid (its pose, time and
  // ROI chain describe the window); the counts summed, the span from first to last point.
  if (m.sensors == 0) {
    static_cast<SweepHeader&>(m) = sweep;
    m.sensors = 0;
  } else {
    const std::int64_t start = std::min(m.start_ns, sweep.start_ns), end = std::max(m.end_ns, sweep.end_ns);
    const std::int64_t arrival = std::max(m.last_packet_arrival_ns, sweep.last_packet_arrival_ns);
    const std::int64_t processing = m.processing_ns + sweep.processing_ns;
    const bool partial = m.partial || sweep.partial;
    const std::uint32_t points_in = m.points_in + sweep.points_in, lost = m.lost_packets + sweep.lost_packets;
    const std::uint32_t truncated = m.truncated + sweep.truncated, sensors = m.sensors;
    // The points' times are after the window's start: earlier now, those in it move along.
    const auto earlier = static_cast<std::int32_t>(m.start_ns - start);
    for (std::int32_t& t : m.time_offset_ns)
      t += earlier;
    for (std::int32_t& t : m.raw.time_offset_ns)
      t += earlier;
    if (!m.filtered && sweep.filtered) static_cast<SweepHeader&>(m) = sweep;  // into reserved room
    m.start_ns = start;
    m.end_ns = end;
    m.last_packet_arrival_ns = arrival;
    m.processing_ns = processing;
    m.partial = partial;
    m.points_in = points_in;
    m.lost_packets = lost;
    m.truncated = truncated;
    m.sensors = sensors;
  }
  m.sensors |= 1U << sensor;
  joined_ns_ = now_ns_;
  if (!sweep.filtered) return;  // a sweep without a valid pose has no points
  const auto shift = static_cast<std::int32_t>(sweep.start_ns - m.start_ns);
  const std::size_t n = append_columns(m, sweep, capacity_, shift);
  m.truncated += static_cast<std::uint32_t>(sweep.size() - n);
  if (n != 0) std::memset(grown(m.sensor_index, n), static_cast<int>(sensor), n);
  const std::size_t raw = append_columns(m.raw, sweep.raw, m.raw.x.capacity(), shift);
  if (raw != 0) std::memset(grown(m.raw_sensor_index, raw), static_cast<int>(sensor), raw);
}

void SweepMerger::emit(SweepSink& sink) {
  merged_.index = index_++;
  merged_.missing = waited_for_ & ~merged_.sensors;
  merged_.merge_wait_ns = std::max<std::int64_t>(0, now_ns_ - joined_ns_);
  merged_.silent = 0;
  for (std::size_t i = 0; i < last_ns_.size(); ++i) {
    if ((merged_.sensors & (1U << i)) == 0 && silent(i, now_ns_)) merged_.silent |= 1U << i;
  }
  if (merged_.missing != 0) ++incomplete_;
  if (merged_.filtered) ++published_;
  sink.on_sweep(merged_);
  merged_.clear_points();
  merged_.sensors = 0;
  merged_.filtered = false;
  open_ = false;
}

}  // namespace trajroi::pipeline
