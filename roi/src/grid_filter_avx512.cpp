// The grid filter's AVX-512 scan: two blocks of sixteen points a step, kept indices compressed
// by mask
// (the scans' shared pieces: grid_filter_scan.hpp). Only these members are instantiated here.
#include "grid_filter_scan.hpp"

namespace trajroi::roi {

#if defined(__x86_64__) || defined(__i386__)
namespace detail {
// What the AVX-512 scan needs to locate sixteen points' cells.
struct Avx512Grid {
  __m512 x0, y0, inv, z_lo, z_hi;
  __m512i nx_i, ny_i, sentinel;
  bool z_limited;
  const int* cells;
};

// As Avx2Block, for sixteen points, with their grid coordinates in cells (whose fractions
// give the sub-cells of the points in boundary cells).
struct Avx512Block {
  __m512i cell;
  __m512 fx;
  __m512 fy;
  bool clean;
};

// The AVX-512 scan does little per point, so each instruction here counts (on an AMD Zen 5
// this block was most of the scan's time, above a memcpy of the cloud): x and y are taken out
// of the four loaded vectors by four permutes, z only when there are z limits; a non-finite
// coordinate anywhere in the block is found by one classification per loaded vector (an
// infinite or NaN intensity also sends the block to the scalar code, which decides it the
// same); and the cells are found by converting with rounding down, so that an unsigned
// comparison with the grid's size rejects what is left of, right of, below or above the grid,
// and NaN, in one step.
__attribute__((target("avx512f,avx512dq"), always_inline)) inline Avx512Block avx512_block(const float* p,
                                                                                           const Avx512Grid& g) {
  const __m512 a = _mm512_loadu_ps(p);                   // points 0–3
  const __m512 b = _mm512_loadu_ps(p + 16);              // points 4–7
  const __m512 c = _mm512_loadu_ps(p + 32);              // points 8–11
  const __m512 d = _mm512_loadu_ps(p + 48);              // points 12–15
  constexpr int kNonFinite = 0x01 | 0x08 | 0x10 | 0x80;  // quiet NaN, +∞, −∞, signalling NaN
  __mmask16 reject =
      _mm512_kor(_mm512_kor(_mm512_fpclass_ps_mask(a, kNonFinite), _mm512_fpclass_ps_mask(b, kNonFinite)),
                 _mm512_kor(_mm512_fpclass_ps_mask(c, kNonFinite), _mm512_fpclass_ps_mask(d, kNonFinite)));
  // x of eight points in lanes 0–7 and their y in lanes 8–15, then x and y of all sixteen.
  const __m512i xy = _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 1, 5, 9, 13, 17, 21, 25, 29);
  const __m512i low = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23);
  const __m512i high = _mm512_add_epi32(low, _mm512_set1_epi32(8));
  const __m512 xy_ab = _mm512_permutex2var_ps(a, xy, b);
  const __m512 xy_cd = _mm512_permutex2var_ps(c, xy, d);
  const __m512 px = _mm512_permutex2var_ps(xy_ab, low, xy_cd);
  const __m512 py = _mm512_permutex2var_ps(xy_ab, high, xy_cd);
  if (g.z_limited) {
    const __m512i z = _mm512_setr_epi32(2, 6, 10, 14, 18, 22, 26, 30, 3, 7, 11, 15, 19, 23, 27, 31);
    const __m512 pz = _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, z, b), low, _mm512_permutex2var_ps(c, z, d));
    const __mmask16 within = _mm512_cmp_ps_mask(pz, g.z_lo, _CMP_GE_OQ) & _mm512_cmp_ps_mask(pz, g.z_hi, _CMP_LE_OQ);
    reject = _mm512_kor(reject, _mm512_knot(within));
  }
  const __m512 fx = _mm512_mul_ps(_mm512_sub_ps(px, g.x0), g.inv);
  const __m512 fy = _mm512_mul_ps(_mm512_sub_ps(py, g.y0), g.inv);
  // Rounded down: a point in [0, n) gets the cell cell_index() gives it (truncation), one in
  // (−1, 0) gets −1, and NaN or a value beyond the int range gets 0x80000000; the last two
  // are above any grid size as unsigned. (The maskz form: GCC 12 warns of the plain form's
  // undefined source.)
  const __m512i ix = _mm512_maskz_cvt_roundps_epi32(0xffff, fx, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __m512i iy = _mm512_maskz_cvt_roundps_epi32(0xffff, fy, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __mmask16 on_grid = _mm512_mask_cmplt_epu32_mask(_mm512_cmplt_epu32_mask(ix, g.nx_i), iy, g.ny_i);
  const __m512i cell = _mm512_mask_add_epi32(g.sentinel, on_grid, _mm512_mullo_epi32(iy, g.nx_i), ix);
  return {cell, fx, fy, reject == 0};
}

// The indices into GridFilter::sub_ of the sub-cells of the lanes of `boundary` (0 in the
// others), the same sub-cells GridFilter::decide() finds: for a point on the grid, fx · kSub
// is exact (kSub is a power of two) and below 2^24, and its integer part is
// kSub · ⌊fx⌋ + ⌊(fx − ⌊fx⌋) · kSub⌋, so its low bits are decide()'s sx. (Gathering their
// values in one 16-lane gather was slower than loading the few that the boundary lanes need.)
template <std::uint32_t kSub, std::uint32_t kFirstBoundary>
__attribute__((target("avx512f"), always_inline)) inline __m512i avx512_sub_index(__mmask16 boundary,
                                                                                  const Avx512Block& block,
                                                                                  __m512i cell_value) {
  static_assert((kSub & (kSub - 1)) == 0, "sub-cells per side must be a power of two");
  // Masked forms: only the boundary lanes matter (and GCC 12 warns of the unmasked forms'
  // undefined source).
  const __mmask16 m = boundary;
  const __m512 per_side = _mm512_set1_ps(static_cast<float>(kSub));
  const __m512i low_bits = _mm512_set1_epi32(static_cast<std::int32_t>(kSub - 1));
  const __m512i sx = _mm512_and_si512(_mm512_maskz_cvttps_epi32(m, _mm512_mul_ps(block.fx, per_side)), low_bits);
  const __m512i sy = _mm512_and_si512(_mm512_maskz_cvttps_epi32(m, _mm512_mul_ps(block.fy, per_side)), low_bits);
  // ((cell value − first boundary value) · kSub + sy) · kSub + sx
  const __m512i side = _mm512_set1_epi32(static_cast<std::int32_t>(kSub));
  const __m512i id = _mm512_maskz_sub_epi32(m, cell_value, _mm512_set1_epi32(kFirstBoundary));
  return _mm512_add_epi32(_mm512_mullo_epi32(_mm512_add_epi32(_mm512_mullo_epi32(id, side), sy), side), sx);
}

// As Avx2Reuse: the cells and values of the previous block (one VLP-16 firing earlier).
struct Avx512Reuse {
  __m512i cell;
  __m512i value;
};

// The values of the block's cells: the previous block's where a lane's cell is the same. On a
// LiDAR sweep most firings change no lane's cell, and of the others most change one (the
// benchmarks' scene: none in 77 % of firings, one in 13 %); on a Zen 5 a gather costs about
// as much as locating the sixteen cells (13 cycles a firing to locate them, 23 with the
// gathers, 21 with a single changed lane read by one load), so one changed lane is loaded alone.
__attribute__((target("avx512f"), always_inline)) inline __m512i avx512_values(__m512i cell, Avx512Reuse& reuse,
                                                                               const int* cells) {
  const __mmask16 changed = _mm512_cmpneq_epi32_mask(cell, reuse.cell);
  if (changed != 0) {
    if ((changed & (changed - 1)) == 0) {
      // The changed lane's cell, brought to lane 0.
      const int index = _mm512_cvtsi512_si32(_mm512_maskz_compress_epi32(changed, cell));
      reuse.value = _mm512_mask_set1_epi32(reuse.value, changed, cells[index]);
    } else {
      reuse.value = _mm512_mask_i32gather_epi32(reuse.value, changed, cell, cells, 4);
    }
    reuse.cell = cell;
  }
  return reuse.value;
}
}  // namespace detail

template <typename RoiSet>
__attribute__((target("avx512f,avx512dq,popcnt"))) std::size_t GridFilter<RoiSet>::scan_avx512(
    std::span<const PointXYZI> points, Scan& scan) const {
  if (points.size() < 16) return 0;
  const FloatZLimits z = float_z_limits(rois_->z_limits());
  const detail::Avx512Grid grid{_mm512_set1_ps(x0_),
                                _mm512_set1_ps(y0_),
                                _mm512_set1_ps(inv_cell_),
                                _mm512_set1_ps(z.lo),
                                _mm512_set1_ps(z.hi),
                                _mm512_set1_epi32(static_cast<std::int32_t>(nx_)),
                                _mm512_set1_epi32(static_cast<std::int32_t>(ny_)),
                                _mm512_set1_epi32(static_cast<std::int32_t>(cells_.size() - 1)),
                                z.limited,
                                reinterpret_cast<const int*>(cells_.data())};
  const float* const base = &points.data()->x;
  std::uint32_t* const out = scan.out;
  std::size_t count = scan.count;
  detail::Avx512Reuse reuse{grid.sentinel, _mm512_setzero_si512()};  // the sentinel reads 0
  const __m512i one = _mm512_set1_epi32(1);
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  // Keeps the block's inside points and those of its boundary points that a candidate ROI
  // accepts, in order. A block with a point to reject goes to the scalar code, which counts
  // why. Since count ≤ first, a 16-slot store at out + count stays within first + 16 ≤ n.
  auto finish = [&](std::size_t first, const detail::Avx512Block& block)
      __attribute__((target("avx512f,avx512dq,popcnt"))) {
    if (!block.clean) [[unlikely]] {
      count = scalar_block(points, first, 16, scan, count);
      return;
    }
    const __m512i cell_value = detail::avx512_values(block.cell, reuse, grid.cells);
    auto keep = static_cast<unsigned>(_mm512_cmpeq_epi32_mask(cell_value, one));
    if (const __mmask16 boundary = _mm512_cmpgt_epu32_mask(cell_value, one); boundary != 0) [[unlikely]] {
      // Their sub-cells, located all at once; only points in boundary sub-cells test candidates.
      alignas(64) std::uint32_t sub_index[16];
      _mm512_store_si512(sub_index, detail::avx512_sub_index<kSub, kFirstBoundary>(boundary, block, cell_value));
      keep |= decide_lanes(boundary, sub_index, points, first);
    }
    const __m512i indices = _mm512_add_epi32(_mm512_set1_epi32(static_cast<std::int32_t>(first)), lane);
    _mm512_storeu_si512(out + count, _mm512_maskz_compress_epi32(static_cast<__mmask16>(keep), indices));
    count += static_cast<std::size_t>(__builtin_popcount(keep));
  };
  // Two blocks per step: both are located before either is looked up.
  const std::size_t ahead = detail::prefetch_distance(points);
  std::size_t i = 0;
  for (; i + 32 <= points.size(); i += 32) {
    detail::prefetch_ahead<32 * sizeof(PointXYZI)>(base + 4 * i, ahead);
    const detail::Avx512Block a = detail::avx512_block(base + 4 * i, grid);
    const detail::Avx512Block b = detail::avx512_block(base + 4 * (i + 16), grid);
    finish(i, a);
    finish(i + 16, b);
  }
  for (; i + 16 <= points.size(); i += 16)
    finish(i, detail::avx512_block(base + 4 * i, grid));
  scan.count = count;
  return i;
}

template std::size_t GridFilter<CircularRoiSet>::scan_avx512(std::span<const PointXYZI>, Scan&) const;
template std::size_t GridFilter<RectangularRoiSet>::scan_avx512(std::span<const PointXYZI>, Scan&) const;
template std::size_t GridFilter<CorridorRoiSet>::scan_avx512(std::span<const PointXYZI>, Scan&) const;
#endif  // x86

}  // namespace trajroi::roi
