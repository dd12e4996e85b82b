#include "trajroi/roi/transform.hpp"

#include <cassert>
#include <cstring>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace trajroi::roi {

Eigen::Isometry3d pose_from_xy_yaw(double x_m, double y_m, double yaw_rad, double z_m) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x_m, y_m, z_m);
  return pose;
}

Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz_m, double roll_rad, double pitch_rad, double yaw_rad) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = xyz_m;
  t.linear() =
      (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  return t;
}

Eigen::Isometry3d pose_from_position_quaternion(const Eigen::Vector3d& position_m,
                                                const Eigen::Quaterniond& orientation) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = orientation.toRotationMatrix();
  t.translation() = position_m;
  return t;
}

namespace {

template <typename Point>
void transform_impl(const Eigen::Isometry3d& target_from_source, std::span<const Point> in, std::span<Point> out) {
  assert(in.size() == out.size());
  using Scalar = decltype(Point{}.x);
  const Eigen::Matrix3d& r = target_from_source.linear();
  const Eigen::Vector3d& t = target_from_source.translation();
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto x = static_cast<double>(in[i].x);
    const auto y = static_cast<double>(in[i].y);
    const auto z = static_cast<double>(in[i].z);
    out[i].x = static_cast<Scalar>(r(0, 0) * x + r(0, 1) * y + r(0, 2) * z + t.x());
    out[i].y = static_cast<Scalar>(r(1, 0) * x + r(1, 1) * y + r(1, 2) * z + t.y());
    out[i].z = static_cast<Scalar>(r(2, 0) * x + r(2, 1) * y + r(2, 2) * z + t.z());
    if constexpr (requires { in[i].intensity; }) out[i].intensity = in[i].intensity;
  }
}

#if defined(__x86_64__) || defined(__i386__)
// A point's x', y', z' in the four lanes of one AVX vector: ((r·0 x + r·1 y) + r·2 z) + t, the
// scalar code's products and sums in its order, without fused multiply-adds (none in this
// target), so each coordinate rounds exactly as there.
__attribute__((target("avx"))) void transform_avx(const Eigen::Isometry3d& target_from_source,
                                                  std::span<const PointXYZI> in, std::span<PointXYZI> out) {
  const Eigen::Matrix3d& r = target_from_source.linear();
  const Eigen::Vector3d& t = target_from_source.translation();
  const __m256d c0 = _mm256_setr_pd(r(0, 0), r(1, 0), r(2, 0), 0.0);
  const __m256d c1 = _mm256_setr_pd(r(0, 1), r(1, 1), r(2, 1), 0.0);
  const __m256d c2 = _mm256_setr_pd(r(0, 2), r(1, 2), r(2, 2), 0.0);
  const __m256d c3 = _mm256_setr_pd(t.x(), t.y(), t.z(), 0.0);
  static_assert(sizeof(PointXYZI) == 4 * sizeof(float));
  for (std::size_t i = 0; i < in.size(); ++i) {
    const __m128 p = _mm_loadu_ps(&in[i].x);                // x y z intensity
    const __m256d d = _mm256_cvtps_pd(p);                   // exact
    const __m256d lo = _mm256_permute2f128_pd(d, d, 0x00);  // x y x y
    const __m256d hi = _mm256_permute2f128_pd(d, d, 0x11);  // z i z i
    const __m256d x = _mm256_permute_pd(lo, 0x0);           // x x x x
    const __m256d y = _mm256_permute_pd(lo, 0xF);           // y y y y
    const __m256d z = _mm256_permute_pd(hi, 0x0);           // z z z z
    __m256d v = _mm256_add_pd(_mm256_mul_pd(c0, x), _mm256_mul_pd(c1, y));
    v = _mm256_add_pd(_mm256_add_pd(v, _mm256_mul_pd(c2, z)), c3);
    _mm_storeu_ps(&out[i].x, _mm_blend_ps(_mm256_cvtpd_ps(v), p, 0x8));  // intensity as it was
  }
}

// Row i of target_from_source applied to four points: ((r_i0 x + r_i1 y) + r_i2 z) + t_i.
__attribute__((target("avx"))) inline __m128 transformed_row(const Eigen::Isometry3d& target_from_source,
                                                             Eigen::Index i, __m256d x, __m256d y, __m256d z) noexcept {
  const Eigen::Matrix3d& r = target_from_source.linear();
  const __m256d sum =
      _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(r(i, 0)), x), _mm256_mul_pd(_mm256_set1_pd(r(i, 1)), y));
  return _mm256_cvtpd_ps(_mm256_add_pd(_mm256_add_pd(sum, _mm256_mul_pd(_mm256_set1_pd(r(i, 2)), z)),
                                       _mm256_set1_pd(target_from_source.translation()(i))));
}

// Four records at a time: their x, y and z side by side (a transpose of the records' first 16
// bytes), each coordinate's products and sums in the scalar order, in doubles, without fused
// multiply-adds (none in this target). Places the whole fours and answers how many.
__attribute__((target("avx"))) std::size_t transform_records_avx(const Eigen::Isometry3d& target_from_source,
                                                                 const std::byte* records, std::size_t count,
                                                                 RecordLayout layout, PointXYZI* out) noexcept {
  const std::size_t stride = layout.stride_bytes;
  const auto intensity = [&](std::size_t k) { return static_cast<int>(records[k * stride + layout.intensity_offset]); };
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4, out += 4) {
    const std::byte* p = records + i * stride;
    __m128 a = _mm_loadu_ps(reinterpret_cast<const float*>(p));  // x y z (and 4 bytes more)
    __m128 b = _mm_loadu_ps(reinterpret_cast<const float*>(p + stride));
    __m128 c = _mm_loadu_ps(reinterpret_cast<const float*>(p + 2 * stride));
    __m128 d = _mm_loadu_ps(reinterpret_cast<const float*>(p + 3 * stride));
    _MM_TRANSPOSE4_PS(a, b, c, d);  // a: four x, b: four y, c: four z
    const __m256d x = _mm256_cvtps_pd(a);
    const __m256d y = _mm256_cvtps_pd(b);
    const __m256d z = _mm256_cvtps_pd(c);
    __m128 gx = transformed_row(target_from_source, 0, x, y, z);
    __m128 gy = transformed_row(target_from_source, 1, x, y, z);
    __m128 gz = transformed_row(target_from_source, 2, x, y, z);
    __m128 gi = _mm_cvtepi32_ps(_mm_setr_epi32(intensity(i), intensity(i + 1), intensity(i + 2), intensity(i + 3)));
    _MM_TRANSPOSE4_PS(gx, gy, gz, gi);
    _mm_storeu_ps(&out[0].x, gx);
    _mm_storeu_ps(&out[1].x, gy);
    _mm_storeu_ps(&out[2].x, gz);
    _mm_storeu_ps(&out[3].x, gi);
  }
  return i;
}
#endif

}  // namespace

void transform_records(const Eigen::Isometry3d& target_from_source, const std::byte* records, std::size_t count,
                       RecordLayout layout, PointXYZI* out) {
  assert(layout.stride_bytes >= 16 && layout.intensity_offset < layout.stride_bytes);
  std::size_t done = 0;
#if defined(__x86_64__) || defined(__i386__)
  if (__builtin_cpu_supports("avx")) done = transform_records_avx(target_from_source, records, count, layout, out);
#endif
  for (std::size_t i = done; i < count; ++i) {
    const std::byte* p = records + i * layout.stride_bytes;
    PointXYZI& o = out[i];
    std::memcpy(&o.x, p, 3 * sizeof(float));
    o.intensity = static_cast<float>(static_cast<std::uint8_t>(p[layout.intensity_offset]));
  }
  const std::span<PointXYZI> rest(out + done, count - done);
  transform_impl<PointXYZI>(target_from_source, rest, rest);
}

void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZI> in,
                      std::span<PointXYZI> out) {
  assert(in.size() == out.size());
#if defined(__x86_64__) || defined(__i386__)
  if (__builtin_cpu_supports("avx")) {
    transform_avx(target_from_source, in, out);
    return;
  }
#endif
  transform_impl(target_from_source, in, out);
}

void transform_points_scalar(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZI> in,
                             std::span<PointXYZI> out) {
  transform_impl(target_from_source, in, out);
}

void transform_points(const Eigen::Isometry3d& target_from_source, std::span<const PointXYZd> in,
                      std::span<PointXYZd> out) {
  transform_impl(target_from_source, in, out);
}

}  // namespace trajroi::roi
