// The grid filter's SSE2 scan: four points a step, boundary cells decided one by one
// (the scans' shared pieces: grid_filter_scan.hpp). Only these members are instantiated here.
#include "grid_filter_scan.hpp"

namespace trajroi::roi {

#if defined(__x86_64__) || defined(__i386__)
template <typename RoiSet>
std::size_t GridFilter<RoiSet>::scan_sse2(std::span<const PointXYZI> points, Scan& scan) const {
  static_assert(sizeof(PointXYZI) == 16);
  if (points.size() < 4) return 0;
  const FloatZLimits z = float_z_limits(rois_->z_limits());
  const bool z_limited = z.limited;
  const __m128 lo = _mm_set1_ps(z.lo);
  const __m128 hi = _mm_set1_ps(z.hi);
  const __m128 x0 = _mm_set1_ps(x0_);
  const __m128 y0 = _mm_set1_ps(y0_);
  const __m128 inv = _mm_set1_ps(inv_cell_);
  const __m128 nx_f = _mm_set1_ps(static_cast<float>(nx_));
  const __m128 ny_f = _mm_set1_ps(static_cast<float>(ny_));
  const __m128 zero = _mm_setzero_ps();
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 max_finite = _mm_set1_ps(std::numeric_limits<float>::max());
  const __m128i sentinel = _mm_set1_epi32(static_cast<std::int32_t>(cells_.size() - 1));
  const std::uint32_t* const cells = cells_.data();
  const float* const base = &points.data()->x;
  std::uint32_t* const out = scan.out;
  std::size_t count = scan.count;
  alignas(16) std::int32_t cell_of[4];
  const std::size_t ahead = detail::prefetch_distance(points);
  std::size_t i = 0;
  for (; i + 4 <= points.size(); i += 4) {
    detail::prefetch_ahead<4 * sizeof(PointXYZI)>(base + 4 * i, ahead);
    __m128 px = _mm_loadu_ps(base + 4 * i);
    __m128 py = _mm_loadu_ps(base + 4 * i + 4);
    __m128 pz = _mm_loadu_ps(base + 4 * i + 8);
    __m128 pi = _mm_loadu_ps(base + 4 * i + 12);
    _MM_TRANSPOSE4_PS(px, py, pz, pi);  // → x, y, z, intensity of the four points
    __m128 pass = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(_mm_and_ps(px, abs_mask), max_finite),
                                        _mm_cmple_ps(_mm_and_ps(py, abs_mask), max_finite)),
                             _mm_cmple_ps(_mm_and_ps(pz, abs_mask), max_finite));
    if (z_limited) pass = _mm_and_ps(pass, _mm_and_ps(_mm_cmpge_ps(pz, lo), _mm_cmple_ps(pz, hi)));
    if (_mm_movemask_ps(pass) != 0xf) [[unlikely]] {
      count = scalar_block(points, i, 4, scan, count);
      continue;
    }
    const __m128 fx = _mm_mul_ps(_mm_sub_ps(px, x0), inv);
    const __m128 fy = _mm_mul_ps(_mm_sub_ps(py, y0), inv);
    const __m128 on_grid = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(fx, zero), _mm_cmplt_ps(fx, nx_f)),
                                      _mm_and_ps(_mm_cmpge_ps(fy, zero), _mm_cmplt_ps(fy, ny_f)));
    // Off-grid lanes are zeroed before converting; on-grid values are ≥ 0, so truncation is
    // the floor, and iy · nx + ix < kMaxCells < 2^24 is exact in float.
    const __m128 ixf = _mm_cvtepi32_ps(_mm_cvttps_epi32(_mm_and_ps(fx, on_grid)));
    const __m128 iyf = _mm_cvtepi32_ps(_mm_cvttps_epi32(_mm_and_ps(fy, on_grid)));
    const __m128i cell = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(iyf, nx_f), ixf));
    const __m128i grid_mask = _mm_castps_si128(on_grid);
    _mm_store_si128(reinterpret_cast<__m128i*>(cell_of),
                    _mm_or_si128(_mm_and_si128(grid_mask, cell), _mm_andnot_si128(grid_mask, sentinel)));
    const std::uint32_t c0 = cells[cell_of[0]];
    const std::uint32_t c1 = cells[cell_of[1]];
    const std::uint32_t c2 = cells[cell_of[2]];
    const std::uint32_t c3 = cells[cell_of[3]];
    if ((c0 | c1 | c2 | c3) >= kFirstBoundary) [[unlikely]] {
      const std::uint32_t c[4] = {c0, c1, c2, c3};
      for (std::size_t k = 0; k < 4; ++k) {
        out[count] = static_cast<std::uint32_t>(i + k);
        count += decide(c[k], static_cast<double>(points[i + k].x), static_cast<double>(points[i + k].y));
      }
      continue;
    }
    out[count] = static_cast<std::uint32_t>(i);
    count += c0;
    out[count] = static_cast<std::uint32_t>(i + 1);
    count += c1;
    out[count] = static_cast<std::uint32_t>(i + 2);
    count += c2;
    out[count] = static_cast<std::uint32_t>(i + 3);
    count += c3;
  }
  scan.count = count;
  return i;
}

template std::size_t GridFilter<CircularRoiSet>::scan_sse2(std::span<const PointXYZI>, Scan&) const;
template std::size_t GridFilter<RectangularRoiSet>::scan_sse2(std::span<const PointXYZI>, Scan&) const;
template std::size_t GridFilter<CorridorRoiSet>::scan_sse2(std::span<const PointXYZI>, Scan&) const;
#endif  // x86

}  // namespace trajroi::roi
