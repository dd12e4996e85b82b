// The processor's per-point work: a sweep's points placed in the global frame a batch at a
// time (one pose per firing, or the sweep's), filtered against the sweep's ROI chain, and the
// kept ones appended to the sweep; and the sweep's end.
#include <algorithm>

#include "columns.hpp"
#include "processor_constants.hpp"
#include "trajroi/pipeline/sweep_processor.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::pipeline {

void SweepProcessor::add_points(Lane& lane, const vlp16::Frame& frame, std::size_t first, SweepSink& sink) {
  if (first == 0 || !lane.in_sweep) {
    start_sweep(lane, frame);
    lane.unfiltered_from = first;
  }
  lane.sweep.last_packet_arrival_ns = arrival_ns_;
  // The points wait until a whole batch has come (a few packets, a millisecond or two of the
  // sensor's): the scan and the placing are set up once per batch, not per packet (as-fast
  // replay of the dual-return corridor: processing thread 12 % less). Their firings' poses
  // are taken then, from the GNSS and IMU samples received until then, in the order of
  // arrival as before (one that came meanwhile interpolates where it was extrapolated). The
  // sweep's end filters the rest.
  filter_points(lane, frame, kScratchPoints, sink);
}

void SweepProcessor::filter_points(Lane& lane, const vlp16::Frame& frame, std::size_t at_least, SweepSink& sink) {
  const std::size_t end = frame.points.size();
  Sweep& s = lane.sweep;
  for (; lane.unfiltered_from < end && end - lane.unfiltered_from >= at_least && s.filtered;
       lane.unfiltered_from = std::min(end, lane.unfiltered_from + kScratchPoints)) {
    const std::size_t i = lane.unfiltered_from;
    const pose::PoseStatus status = filter_batch(lane, frame, i, std::min(end, i + kScratchPoints), sink);
    if (status != pose::PoseStatus::kValid) {
      s.filtered = false;
      s.pose_status = status;
      s.pose_measured = lane.firing.measured();
      s.pose_limit = lane.firing.limit();
      s.clear_points();
      have_hint_ = false;
    }
  }
}

pose::PoseStatus SweepProcessor::filter_batch(Lane& lane, const vlp16::Frame& frame, std::size_t first, std::size_t end,
                                              SweepSink& sink) {
  const auto place_run = [&](std::size_t from, std::size_t to, const Eigen::Isometry3d& global_from_lidar) {
    roi::transform_records(global_from_lidar, std::span(frame.points).subspan(from, to - from),
                           scratch_.data() + (from - first));
  };
  if (config_.pose_mode == PoseMode::kPerSweep) {
    place_run(first, end, lane.sweep_sensor_pose);
  } else {
    // Per firing: the points of one firing period (in time order) share a pose.
    for (std::size_t i = first; i < end;) {
      pose::PoseStatus status{};
      const Eigen::Isometry3d* pose = lane.firing.at(frame.start_time_ns + frame.points[i].time_offset_ns, status);
      if (pose == nullptr) return status;
      // The following points the same pose covers, in the frame's time offsets.
      const pose::FiringPoses::Window window = lane.firing.window_after(frame.start_time_ns);
      std::size_t j = i + 1;
      while (j < end && window.contains(frame.points[j].time_offset_ns))
        ++j;
      place_run(i, j, *pose);
      i = j;
    }
  }
  const std::span<const roi::PointXYZI> placed(scratch_.data(), end - first);
  sink.on_placed(frame, first, placed);
  if (config_.outputs.raw_points) keep_raw(lane, frame, first, end);
  (void)lane.chain.filter(placed, kept_);
  Sweep& s = lane.sweep;
  const std::size_t room =
      config_.buffers.max_points_per_sweep - std::min(config_.buffers.max_points_per_sweep, s.size());
  const std::size_t n = std::min(room, kept_.size());
  s.truncated += static_cast<std::uint32_t>(kept_.size() - n);
  // Grown once, then written through pointers.
  s.make_resident_to(s.size() + n);
  float* const x = grown(s.x, n);
  float* const y = grown(s.y, n);
  float* const z = grown(s.z, n);
  std::uint8_t* const intensity = grown(s.intensity, n);
  std::uint8_t* const ring = grown(s.ring, n);
  std::uint8_t* const return_type = grown(s.return_type, n);
  std::int32_t* const time_offset_ns = grown(s.time_offset_ns, n);
  // The sources in locals too: every byte stored may alias anything, so the compiler would
  // reload the vectors' data pointers after each one.
  const std::uint32_t* const kept = kept_.data();
  const roi::PointXYZI* const placed_at = scratch_.data();
  const vlp16::Point* const batch = frame.points.data() + first;
  for (std::size_t k = 0; k < n; ++k) {
    const roi::PointXYZI& g = placed_at[kept[k]];
    const vlp16::Point& p = batch[kept[k]];
    x[k] = g.x;
    y[k] = g.y;
    z[k] = g.z;
    intensity[k] = p.intensity;
    ring[k] = p.ring;
    return_type[k] = static_cast<std::uint8_t>(p.return_type);
    time_offset_ns[k] = static_cast<std::int32_t>(p.time_offset_ns);
  }
  if (keep_indices_) {
    std::uint32_t* const index = grown(s.point_index, n);
    for (std::size_t k = 0; k < n; ++k)
      index[k] = static_cast<std::uint32_t>(first + kept[k]);
  }
  return pose::PoseStatus::kValid;
}

std::size_t raw_points_capacity(const DaemonConfig& config) noexcept {
  return config.outputs.raw_points ? config.buffers.max_points_per_sweep / config.outputs.raw_points_decimation : 0;
}

void SweepProcessor::keep_raw(Lane& lane, const vlp16::Frame& frame, std::size_t first, std::size_t end) {
  const std::size_t every = config_.outputs.raw_points_decimation;
  PointColumns& raw = lane.sweep.raw;
  const std::size_t capacity = raw.x.capacity();
  for (std::size_t i = (first + every - 1) / every * every; i < end && raw.size() < capacity; i += every) {
    const roi::PointXYZI& g = scratch_[i - first];
    const vlp16::Point& p = frame.points[i];
    raw.x.push_back(g.x);
    raw.y.push_back(g.y);
    raw.z.push_back(g.z);
    raw.intensity.push_back(p.intensity);
    raw.ring.push_back(p.ring);
    raw.return_type.push_back(static_cast<std::uint8_t>(p.return_type));
    raw.time_offset_ns.push_back(static_cast<std::int32_t>(p.time_offset_ns));
  }
}

void SweepProcessor::end_sweep(Lane& lane, const vlp16::Frame& frame, SweepSink& sink) {
  if (!lane.in_sweep) {
    start_sweep(lane, frame);  // a frame of packets without points
    lane.unfiltered_from = frame.points.size();
  }
  filter_points(lane, frame, 1, sink);
  lane.in_sweep = false;
  Sweep& s = lane.sweep;
  s.index = frame.index;
  s.end_ns = frame.end_time_ns;
  s.partial = frame.partial;
  s.return_mode = static_cast<std::uint8_t>(frame.return_mode);
  s.points_in = static_cast<std::uint32_t>(frame.points.size());
  s.lost_packets = frame.lost_packets;
  ++counters_.sweeps;
  counters_.points_in += frame.points.size();
  if (s.filtered) {
    ++counters_.sweeps_filtered;
    counters_.points_kept += s.size();
    counters_.points_truncated += s.truncated;
  } else {
    ++counters_.sweeps_without_pose;
    s.clear_points();
  }
  if (merger_) {
    merger_->add(lane.index, s, now_ns_, sink);
  } else {
    sink.on_sweep(s);
  }
}

}  // namespace trajroi::pipeline
