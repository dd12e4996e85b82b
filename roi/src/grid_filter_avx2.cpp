// The grid filter's AVX2 scan: two blocks of eight points a step, cells gathered, boundary sub-cells
// located for a whole block at once
// (the scans' shared pieces: grid_filter_scan.hpp). Only these members are instantiated here.
#include "grid_filter_scan.hpp"

namespace trajroi::roi {

#if defined(__x86_64__) || defined(__i386__)
template <typename RoiSet>
unsigned GridFilter<RoiSet>::decide_lanes_avx2(unsigned boundary, const std::uint32_t* sub_index,
                                               std::span<const PointXYZI> points, std::size_t first) const {
  return decide_lanes(boundary, sub_index, points, first);
}

namespace detail {
// For each 8-bit keep mask, the lanes to keep, packed to the front: compaction by one
// permutevar8x32.
struct CompressTable {
  alignas(32) std::uint32_t lanes[256][8];
  constexpr CompressTable() : lanes{} {
    for (unsigned mask = 0; mask < 256; ++mask) {
      unsigned n = 0;
      for (unsigned lane = 0; lane < 8; ++lane) {
        if ((mask >> lane) & 1u) lanes[mask][n++] = lane;
      }
    }
  }
};
inline constexpr CompressTable kCompress{};
}  // namespace detail

namespace detail {
// What the AVX2 scan needs to locate eight points' cells.
struct Avx2Grid {
  __m256 x0, y0, inv, nx_f, ny_f, z_lo, z_hi;
  __m256i nx_i, sentinel;
  bool z_limited;
  const int* cells;
};

// The cells (indices into the cell table) of the eight points at `p` (x, y, z, intensity
// each), in point order, the sentinel for off-grid points; `clean` is false when one of them
// is non-finite or outside the z limits.
struct Avx2Block {
  __m256i cell;
  bool clean;
};

// The x, y and z of the eight points at `p`, in lane order 0 2 4 6 1 3 5 7 (what the
// transposition gives), and their grid coordinates in cells.
struct Avx2Points {
  __m256 x, y, z;
  __m256 fx, fy;
};

__attribute__((target("avx2"), always_inline)) inline Avx2Points avx2_points(const float* p, const Avx2Grid& g) {
  const __m256 a = _mm256_loadu_ps(p);         // points 0, 1
  const __m256 b = _mm256_loadu_ps(p + 8);     // points 2, 3
  const __m256 c = _mm256_loadu_ps(p + 16);    // points 4, 5
  const __m256 d = _mm256_loadu_ps(p + 24);    // points 6, 7
  const __m256 t0 = _mm256_unpacklo_ps(a, b);  // x0 x2 y0 y2 | x1 x3 y1 y3
  const __m256 t1 = _mm256_unpackhi_ps(a, b);  // z0 z2 . .   | z1 z3 . .
  const __m256 t2 = _mm256_unpacklo_ps(c, d);
  const __m256 t3 = _mm256_unpackhi_ps(c, d);
  const __m256 px = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));  // x 0 2 4 6 | 1 3 5 7
  const __m256 py = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
  const __m256 pz = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
  return {px, py, pz, _mm256_mul_ps(_mm256_sub_ps(px, g.x0), g.inv), _mm256_mul_ps(_mm256_sub_ps(py, g.y0), g.inv)};
}

// The transposition's lane order put back to point order.
__attribute__((target("avx2"), always_inline)) inline __m256i avx2_natural(__m256i v) {
  return _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7));
}

__attribute__((target("avx2"), always_inline)) inline Avx2Block avx2_block(const float* p, const Avx2Grid& g) {
  const auto [px, py, pz, fx, fy] = avx2_points(p, g);
  // v − v is 0 for every finite v and NaN for ±∞ and NaN: the sum is 0 when all three are finite.
  const __m256 zero = _mm256_setzero_ps();
  const __m256 finite_sum =
      _mm256_add_ps(_mm256_add_ps(_mm256_sub_ps(px, px), _mm256_sub_ps(py, py)), _mm256_sub_ps(pz, pz));
  __m256 pass = _mm256_cmp_ps(finite_sum, zero, _CMP_EQ_OQ);
  if (g.z_limited) {
    pass = _mm256_and_ps(pass,
                         _mm256_and_ps(_mm256_cmp_ps(pz, g.z_lo, _CMP_GE_OQ), _mm256_cmp_ps(pz, g.z_hi, _CMP_LE_OQ)));
  }
  // fx ≥ 0 and fy ≥ 0 as min(fx, fy) ≥ 0 (a NaN, from a non-finite point, makes the block unclean).
  const __m256 on_grid =
      _mm256_and_ps(_mm256_cmp_ps(_mm256_min_ps(fx, fy), zero, _CMP_GE_OQ),
                    _mm256_and_ps(_mm256_cmp_ps(fx, g.nx_f, _CMP_LT_OQ), _mm256_cmp_ps(fy, g.ny_f, _CMP_LT_OQ)));
  // Off-grid lanes are zeroed before converting; on-grid values are ≥ 0 (truncation floors).
  const __m256i ix = _mm256_cvttps_epi32(_mm256_and_ps(fx, on_grid));
  const __m256i iy = _mm256_cvttps_epi32(_mm256_and_ps(fy, on_grid));
  const __m256i cell = _mm256_blendv_epi8(g.sentinel, _mm256_add_epi32(_mm256_mullo_epi32(iy, g.nx_i), ix),
                                          _mm256_castps_si256(on_grid));
  return {avx2_natural(cell), _mm256_movemask_ps(pass) == 0xff};
}

// A LiDAR cloud in firing order brings the same laser back every block or two, and its
// consecutive returns mostly land in the same cell: the scans keep the cells and values of
// an earlier block and gather only the lanes whose cell has changed (none, most of the
// time). Any order gives the same result; this one only makes it cheaper.
struct Avx2Reuse {
  __m256i cell;
  __m256i value;  // the cell table's entries for `cell`
};

__attribute__((target("avx2"), always_inline)) inline __m256i avx2_values(__m256i cell, Avx2Reuse& reuse,
                                                                          const int* cells) {
  const __m256i same = _mm256_cmpeq_epi32(cell, reuse.cell);
  if (_mm256_movemask_ps(_mm256_castsi256_ps(same)) != 0xff) {
    reuse.value =
        _mm256_mask_i32gather_epi32(reuse.value, cells, cell, _mm256_xor_si256(same, _mm256_set1_epi32(-1)), 4);
    reuse.cell = cell;
  }
  return reuse.value;
}

// Writes the indices first … first + 7 whose bit is set in `keep` to out, packed; returns
// how many. Writes eight slots at `out`.
__attribute__((target("avx2,popcnt"), always_inline)) inline std::size_t avx2_emit(unsigned keep, std::size_t first,
                                                                                   std::uint32_t* out) {
  const __m256i indices =
      _mm256_add_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(first)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  const __m256i packed =
      _mm256_permutevar8x32_epi32(indices, _mm256_load_si256(reinterpret_cast<const __m256i*>(kCompress.lanes[keep])));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), packed);
  return static_cast<std::size_t>(__builtin_popcount(keep));
}

// Lane masks of the values equal to 1 (inside) and above 1 (boundary ids).
__attribute__((target("avx2"), always_inline)) inline unsigned avx2_inside(__m256i value) {
  return static_cast<unsigned>(
      _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(value, _mm256_set1_epi32(1)))));
}
__attribute__((target("avx2"), always_inline)) inline unsigned avx2_boundary(__m256i value) {
  return static_cast<unsigned>(
      _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(value, _mm256_set1_epi32(1)))));
}

__attribute__((target("avx2"), always_inline)) inline void avx2_store(__m256i value, std::uint32_t* out) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), value);
}

// As avx512_sub_index, for the eight points at `p` with cell values `cell_value` (in point
// order): the indices into GridFilter::sub_ of their sub-cells, meaningful in the boundary
// lanes only. Their grid coordinates are located again (avx2_points, as in avx2_block): this
// runs for one block in seven or so, and keeping them from avx2_block would cost the main
// loop registers it does not have.
template <std::uint32_t kSub, std::uint32_t kFirstBoundary>
__attribute__((target("avx2"), always_inline)) inline __m256i avx2_sub_index(const float* p, const Avx2Grid& g,
                                                                             __m256i cell_value) {
  const Avx2Points at = avx2_points(p, g);
  const __m256 per_side = _mm256_set1_ps(static_cast<float>(kSub));
  const __m256i last = _mm256_set1_epi32(static_cast<std::int32_t>(kSub - 1));
  const __m256 frac_x = _mm256_sub_ps(at.fx, _mm256_cvtepi32_ps(_mm256_cvttps_epi32(at.fx)));
  const __m256 frac_y = _mm256_sub_ps(at.fy, _mm256_cvtepi32_ps(_mm256_cvttps_epi32(at.fy)));
  const __m256i sx = avx2_natural(_mm256_min_epu32(_mm256_cvttps_epi32(_mm256_mul_ps(frac_x, per_side)), last));
  const __m256i sy = avx2_natural(_mm256_min_epu32(_mm256_cvttps_epi32(_mm256_mul_ps(frac_y, per_side)), last));
  // ((cell value − first boundary value) · kSub + sy) · kSub + sx
  const __m256i side = _mm256_set1_epi32(static_cast<std::int32_t>(kSub));
  const __m256i id = _mm256_sub_epi32(cell_value, _mm256_set1_epi32(kFirstBoundary));
  return _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(_mm256_mullo_epi32(id, side), sy), side), sx);
}
}  // namespace detail

template <typename RoiSet>
__attribute__((target("avx2,popcnt"))) std::size_t GridFilter<RoiSet>::scan_avx2(std::span<const PointXYZI> points,
                                                                                 Scan& scan) const {
  if (points.size() < 8) return 0;
  const FloatZLimits z = float_z_limits(rois_->z_limits());
  const detail::Avx2Grid grid{_mm256_set1_ps(x0_),
                              _mm256_set1_ps(y0_),
                              _mm256_set1_ps(inv_cell_),
                              _mm256_set1_ps(static_cast<float>(nx_)),
                              _mm256_set1_ps(static_cast<float>(ny_)),
                              _mm256_set1_ps(z.lo),
                              _mm256_set1_ps(z.hi),
                              _mm256_set1_epi32(static_cast<std::int32_t>(nx_)),
                              _mm256_set1_epi32(static_cast<std::int32_t>(cells_.size() - 1)),
                              z.limited,
                              reinterpret_cast<const int*>(cells_.data())};
  const float* const base = &points.data()->x;
  std::uint32_t* const out = scan.out;
  std::size_t count = scan.count;
  // Keeps the block's inside points and those of its boundary points a candidate ROI
  // accepts, in order. A block with a point to reject goes to the scalar code, which counts
  // why. Since count ≤ first, an 8-slot store at out + count stays within first + 8 ≤ n.
  auto finish = [&](std::size_t first, const detail::Avx2Block& block, detail::Avx2Reuse& reuse)
      __attribute__((target("avx2,popcnt"))) {
    if (!block.clean) [[unlikely]] {
      count = scalar_block(points, first, 8, scan, count);
      return;
    }
    const __m256i value = detail::avx2_values(block.cell, reuse, grid.cells);
    unsigned keep = detail::avx2_inside(value);
    if (const unsigned boundary = detail::avx2_boundary(value); boundary != 0) [[unlikely]] {
      // Their sub-cells, located all at once; only points in boundary sub-cells test candidates.
      alignas(32) std::uint32_t sub_index[8];
      detail::avx2_store(detail::avx2_sub_index<kSub, kFirstBoundary>(base + 4 * first, grid, value), sub_index);
      keep |= decide_lanes_avx2(boundary, sub_index, points, first);
    }
    count += detail::avx2_emit(keep, first, out + count);
  };
  // Two blocks per step (the first and second half of a VLP-16 firing), each reusing the
  // values of the same half one step earlier. All reused cells start as the sentinel.
  detail::Avx2Reuse first_half{grid.sentinel, _mm256_setzero_si256()};
  detail::Avx2Reuse second_half = first_half;
  const std::size_t ahead = detail::prefetch_distance(points);
  std::size_t i = 0;
  for (; i + 16 <= points.size(); i += 16) {
    detail::prefetch_ahead<16 * sizeof(PointXYZI)>(base + 4 * i, ahead);
    const detail::Avx2Block a = detail::avx2_block(base + 4 * i, grid);
    const detail::Avx2Block b = detail::avx2_block(base + 4 * (i + 8), grid);
    finish(i, a, first_half);
    finish(i + 8, b, second_half);
  }
  for (; i + 8 <= points.size(); i += 8)
    finish(i, detail::avx2_block(base + 4 * i, grid), first_half);
  scan.count = count;
  return i;
}

template unsigned GridFilter<CircularRoiSet>::decide_lanes_avx2(unsigned, const std::uint32_t*,
                                                                std::span<const PointXYZI>, std::size_t) const;
template std::size_t GridFilter<CircularRoiSet>::scan_avx2(std::span<const PointXYZI>, Scan&) const;
template unsigned GridFilter<RectangularRoiSet>::decide_lanes_avx2(unsigned, const std::uint32_t*,
                                                                   std::span<const PointXYZI>, std::size_t) const;
template std::size_t GridFilter<RectangularRoiSet>::scan_avx2(std::span<const PointXYZI>, Scan&) const;
template unsigned GridFilter<CorridorRoiSet>::decide_lanes_avx2(unsigned, const std::uint32_t*,
                                                                std::span<const PointXYZI>, std::size_t) const;
template std::size_t GridFilter<CorridorRoiSet>::scan_avx2(std::span<const PointXYZI>, Scan&) const;
#endif  // x86

}  // namespace trajroi::roi
