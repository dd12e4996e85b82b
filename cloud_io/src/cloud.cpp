#include "trajroi/cloud_io/cloud.hpp"

#include <algorithm>
#include <cmath>

namespace trajroi::cloud_io {

void Cloud::clear() {
  x.clear();
  y.clear();
  z.clear();
  intensity.clear();
  time_s.clear();
  ring.clear();
  return_type.clear();
}

void Cloud::reserve(std::size_t n) {
  x.reserve(n);
  y.reserve(n);
  z.reserve(n);
  intensity.reserve(n);
  time_s.reserve(n);
  ring.reserve(n);
  return_type.reserve(n);
}

void Cloud::push(float px, float py, float pz, float i, std::uint16_t r, float t, std::uint8_t rt) {
  x.push_back(px);
  y.push_back(py);
  z.push_back(pz);
  intensity.push_back(i);
  ring.push_back(r);
  time_s.push_back(t);
  return_type.push_back(rt);
}

Cloud from_points(const trajroi::points_t& m) {
  Cloud c;
  const auto n = static_cast<std::size_t>(std::max(0, m.num_points));
  c.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    c.push(m.x[i], m.y[i], m.z[i], static_cast<float>(m.intensity[i]), static_cast<std::uint8_t>(m.ring[i]),
           static_cast<float>(static_cast<double>(m.time_offset_ns[i]) * 1e-9),
           static_cast<std::uint8_t>(m.return_type[i]));
  }
  c.start_utc_ns = m.sweep_start_utc_ns;
  c.return_mode = static_cast<std::uint8_t>(m.return_mode);
  c.comment = "trajroi: sweep " + std::to_string(m.sweep_index) + ", trajectory " + std::to_string(m.trajectory_id) +
              ", global frame (x east, y north, z up, m)";
  return c;
}

void Accumulator::add(const Cloud& sweep, std::int64_t sweep_start_ns) {
  if (sweeps_++ == 0) {
    first_start_ns_ = sweep_start_ns;
    cloud_.start_utc_ns = sweep.start_utc_ns;
    cloud_.return_mode = sweep.return_mode;
    cloud_.comment = "trajroi: accumulated map; the first: " + sweep.comment;
  }
  const double offset_s = static_cast<double>(sweep_start_ns - first_start_ns_) * 1e-9;
  for (std::size_t i = 0; i < sweep.size(); ++i) {
    if (voxel_m_ > 0.0) {
      // 21 bits per axis: ±1 048 km at 1 m voxels, ±10 km at 1 cm.
      const auto cell = [this](float v) {
        return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(static_cast<double>(v) / voxel_m_)) +
                                          (1 << 20)) &
               0x1FFFFF;
      };
      const std::uint64_t key = (cell(sweep.x[i]) << 42) | (cell(sweep.y[i]) << 21) | cell(sweep.z[i]);
      if (!occupied_.insert(key).second) continue;
    }
    cloud_.push(sweep.x[i], sweep.y[i], sweep.z[i], sweep.intensity[i], sweep.ring[i],
                static_cast<float>(offset_s + static_cast<double>(sweep.time_s[i])), sweep.return_type[i]);
  }
}

}  // namespace trajroi::cloud_io
