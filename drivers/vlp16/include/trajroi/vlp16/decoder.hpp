#pragma once

// Decoding of Velodyne data packets (the VLP-16's and the models of model.hpp) into points in
// the sensor frame.
//
// Sensor frame (REP-103): x forward (azimuth 0), y left, z up, metres. The VLP-16 azimuth
// grows clockwise seen from above. With ω the laser's vertical angle, R the corrected range,
// θ = azimuth − rot_correction, v and h the laser's vertical and horizontal offsets, this is
// the calibration model of the velodyne/nebula drivers (whose calibration files we read):
//   r_xy = R cos ω − v sin ω
//   x = r_xy cos θ + h sin θ,   y = −r_xy sin θ + h cos θ,   z = R sin ω + v cos ω.
// With v = h = 0 this is the VLP-16 manual's x_m = R cos ω sin α, y_m = R cos ω cos α (manual
// frame: y forward) turned into REP-103 (x = y_m, y = −x_m).
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "trajroi/vlp16/model.hpp"
#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {

// One laser's geometry, as in the velodyne/nebula calibration files (angles in radians).
struct LaserCalibration {
  double vert_angle_rad = 0.0;      // ω
  double rot_correction_rad = 0.0;  // subtracted from the azimuth
  double vert_offset_m = 0.0;       // v
  double horiz_offset_m = 0.0;      // h
  double dist_correction_m = 0.0;   // added to the range
};

// Geometry of the lasers (16 or 32), indexed by laser id (firing order 0 … laser_count − 1).
struct Calibration {
  std::size_t laser_count = kLasers;
  std::array<LaserCalibration, kMaxLasers> lasers{};
  // The VLP-16 manual's values: vertical angles −15, 1, −13, 3, … , −1, 15° in firing order,
  // and its vertical offset corrections (11.2 mm … −11.2 mm).
  [[nodiscard]] static Calibration vlp16_default();
  // The model's manual values (model_calibration.cpp); the VLP-16's is vlp16_default().
  [[nodiscard]] static Calibration for_model(Model model);
  // The rank of each laser by vertical angle (0 = lowest): the "ring" of point clouds.
  [[nodiscard]] std::array<std::uint8_t, kMaxLasers> rings() const;
};

// Reads the velodyne/nebula calibration YAML (`lasers: [{laser_id, vert_correction,
// rot_correction, vert_offset_correction, horiz_offset_correction, dist_correction, …}]`,
// angles in radians, lengths in metres): 16 or 32 lasers, each id 0 … n − 1 exactly once
// (`num_lasers`, when present, must agree). Throws std::runtime_error naming `source`, the
// line, the laser and the key on any problem.
[[nodiscard]] Calibration parse_calibration_yaml(std::string_view text, std::string_view source);
// Reads VeloView's calibration XML (Velodyne's db.xml: <points_><item><px><id_>,
// <rotCorrection_>, <vertCorrection_> in degrees, <distCorrection_>, <vertOffsetCorrection_>,
// <horizOffsetCorrection_> in centimetres): 16 or 32 lasers. Throws std::runtime_error naming
// `source`, the line and the element.
[[nodiscard]] Calibration parse_calibration_xml(std::string_view text, std::string_view source);
[[nodiscard]] bool looks_like_calibration_xml(std::string_view text) noexcept;
// Either form, told by its content.
[[nodiscard]] Calibration parse_calibration_file(std::string_view text, std::string_view source);

// Which return of a dual-return pair a point is. In dual mode each firing fills a block pair:
// the even block holds the last return, the odd block the strongest (or, when the strongest
// is the last, the second strongest). Identical returns give one point, kBoth.
enum class ReturnType : std::uint8_t { kStrongest = 1, kLast = 2, kBoth = 3 };
[[nodiscard]] std::string_view to_string(ReturnType type) noexcept;

struct Point {
  float x;  // sensor frame, m
  float y;
  float z;
  float distance_m;              // corrected range
  float azimuth_deg;             // interpolated firing azimuth, [0, 360), before rot_correction
  std::uint32_t time_offset_ns;  // after the packet's first firing (its timestamp); in a
                                 // Frame, after the frame's start instead
  std::uint8_t intensity;        // calibrated reflectivity
  std::uint8_t laser;            // laser id 0 … 15 (31 for the 32-laser models), firing order
  std::uint8_t ring;             // rank by vertical angle, 0 = lowest
  ReturnType return_type;
};

// Up to this azimuth step between firings (5°; a VLP-16 at 20 Hz steps 0.8°) the in-block
// rotation δ ≤ 0.09 rad is turned into cos/sin by series, whose truncation error (δ⁷/5040 <
// 1e-11) is far below float resolution, and centidegrees become degrees by a multiplication
// (the same float as the division). Larger steps only occur in damaged data; they take the
// library cos/sin and the division.
inline constexpr std::uint32_t kSeriesGapLimit_cdeg = 500;

struct DecodeOptions {
  double min_range_m = 0.0;  // inclusive; ranges outside are dropped (and counted)
  double max_range_m = std::numeric_limits<double>::infinity();
};

// The two builds of the decoder (the same arithmetic in the same order: the same points):
// compiled for every x86-64, and for processors with AVX2.
enum class DecoderBuild : std::uint8_t { kBaseline, kAvx2 };
[[nodiscard]] std::string_view to_string(DecoderBuild build) noexcept;

// Which build PacketDecoder::decode() runs here. Where the processor has AVX2, both decode
// the same synthetic packets (dual and strongest return, every channel returning) and the
// AVX2 build is taken unless the baseline is clearly (3 %) faster. TRAJROI_SIMD forces it:
// scalar or sse2 the baseline, avx2 or avx512 the AVX2 build (where the processor has it).
struct DecoderCalibration {
  DecoderBuild chosen = DecoderBuild::kBaseline;
  bool forced = false;                 // by TRAJROI_SIMD: nothing was timed
  bool avx2_available = false;         // the processor has AVX2
  double baseline_ns_per_point = 0.0;  // as timed (0: not timed)
  double avx2_ns_per_point = 0.0;
};
// Times the builds now (`forced`: TRAJROI_SIMD's value, or null).
[[nodiscard]] DecoderCalibration calibrate_decoder(const char* forced);
// The process's choice: calibrate_decoder(TRAJROI_SIMD) once, at the first call (the first
// decode() makes it if nothing did before).
[[nodiscard]] const DecoderCalibration& decoder_calibration();
// "avx2 (avx2 5.12, baseline 5.31 ns per point)", "baseline (forced by TRAJROI_SIMD)",
// "baseline (no AVX2)".
[[nodiscard]] std::string describe(const DecoderCalibration& calibration);

// Room in `out` for one more packet's points, grown rarely (by 64 packets' worth at a time):
// decode() and the stream decoder's points decoded ahead grow a frame alike.
inline void reserve_packet_room(std::vector<Point>& out) {
  if (out.capacity() - out.size() < kPointsPerPacket) out.reserve(out.size() + kPointsPerPacket * 64);
}

class PacketDecoder {
 public:
  // `calibration` must hold the model's number of lasers (std::invalid_argument otherwise).
  explicit PacketDecoder(const Calibration& calibration, DecodeOptions options = {}, Model model = Model::kVlp16);
  [[nodiscard]] Model model() const noexcept { return model_; }

  struct Result {
    std::size_t points = 0;          // appended to `out`
    std::size_t no_return = 0;       // zero distance
    std::size_t out_of_range = 0;    // outside [min_range, max_range]
    std::size_t merged_returns = 0;  // dual mode: second returns identical to the first
    // points + no_return + out_of_range + merged_returns = 384 per packet
    // Bounds of the azimuths and time offsets of every channel of every firing decoded, points
    // or not (those of the points lie within; nothing decoded: +inf, −inf, 0).
    float azimuth_min_deg = std::numeric_limits<float>::infinity();
    float azimuth_max_deg = -std::numeric_limits<float>::infinity();
    std::uint32_t time_offset_max_ns = 0;
  };

  // Appends the points of one packet that validate_data_packet() accepted. Never reads
  // outside the packet; allocates only if `out` must grow.
  Result decode(std::span<const std::uint8_t> packet, std::vector<Point>& out) const;
  // decode() as compiled for every x86-64, and for processors with AVX2 (the same arithmetic
  // in the same order, without fused multiply-adds: the same points). decode() calls the one
  // decoder_calibration() chose; these are for tests and benchmarks (decode_avx2 only where
  // the processor has AVX2).
  Result decode_baseline(std::span<const std::uint8_t> packet, std::vector<Point>& out) const;
  Result decode_avx2(std::span<const std::uint8_t> packet, std::vector<Point>& out) const;

 private:
  struct Laser {
    double cos_vert, sin_vert;
    double cos_rot, sin_rot;
    double horiz_offset_m, dist_correction_m;
    double offset_sin_vert, offset_cos_vert;  // the vertical offset · sin_vert, · cos_vert
    std::uint8_t ring;
  };
  // Per channel of one firing (pair): cos θ, sin θ of its direction and the azimuth it reports.
  struct Directions {
    std::array<double, kFiringsPerBlock * kLasers> cos_a, sin_a;
    std::array<float, kFiringsPerBlock * kLasers> azimuth_deg;
  };
  struct AzimuthTable;
  struct StepTables;
  struct Tables {
    const AzimuthTable& azimuth;
    const StepTables& steps;
  };
  // The directions of the channels of a block at `azimuth`, advancing by `gap` over it, in
  // loops without branches (the compiler vectorizes them).
  void directions(const Tables& tables, std::uint16_t azimuth, std::uint32_t gap, Directions& d) const noexcept;
  Result decode_body(std::span<const std::uint8_t> packet, std::vector<Point>& out) const;
  // Built at the first call (the first packet decoded: thread-safe), then shared: the azimuths'
  // cos/sin by every decoder, the in-block steps by the decoders of one model.
  [[nodiscard]] static const AzimuthTable& azimuth_table();
  [[nodiscard]] static const StepTables& step_tables(Model model);
  Model model_;
  DecodeOptions options_;
  double distance_unit_m_;
  std::array<Laser, kMaxLasers> lasers_{};
  std::array<std::uint8_t, kFiringsPerBlock * kLasers> channel_laser_{};  // per channel of a block
  bool rotation_corrected_ = false;                                       // some rot_correction ≠ 0
  // Per channel 0 … 31 of a block: its firing time after the block's first, as a fraction of
  // the block's duration (for azimuth interpolation).
  std::array<double, kFiringsPerBlock * kLasers> azimuth_fraction_{};
  // Per firing pair (12 in single mode, 6 in dual) and channel: ns after the packet's first
  // firing, rounded once here.
  std::array<std::array<std::uint32_t, kFiringsPerBlock * kLasers>, kBlocks> time_ns_{};
};

}  // namespace trajroi::vlp16
