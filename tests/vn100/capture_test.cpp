// The VN-100 framer and decoder on the LoggerWavesInIce SD-card logs (../shared/data/vectornav):
// frame counts from the data README and every decoded value against the author's CSV.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "numeric_csv.hpp"
#include "stream_feed.hpp"
#include "test_data.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::vn100 {
namespace {

using test::as_bytes;

struct Parsed {
  std::vector<Sample> samples;
  std::vector<std::vector<std::uint8_t>> frames;
  framing::FramerCounters counters;
};

Parsed parse(std::span<const std::uint8_t> bytes, std::size_t chunk = 0) {
  Framer framer;
  Parsed out;
  const auto sink = [&](std::span<const std::uint8_t> frame) {
    Sample s;
    EXPECT_TRUE(decode(frame, s));
    out.samples.push_back(s);
    out.frames.emplace_back(frame.begin(), frame.end());
  };
  test::feed_in_chunks(framer, bytes, chunk, sink);
  out.counters = framer.counters();
  return out;
}

// The 29 values of a frame in the author's CSV column order: uncompensated mag, accel, gyro,
// temperature, pressure, yaw/pitch/roll, DCM, MagNED, AccNED.
std::vector<double> csv_order(const Sample& s) {
  std::vector<double> v;
  const auto add = [&](const auto& values) {
    for (const float x : values)
      v.push_back(static_cast<double>(x));
  };
  add(s.uncomp_mag_gauss);
  add(s.uncomp_accel_mps2);
  add(s.uncomp_gyro_rps);
  v.push_back(static_cast<double>(s.temperature_c));
  v.push_back(static_cast<double>(s.pressure_kpa));
  add(s.ypr_deg);
  add(s.dcm);
  add(s.mag_ned_gauss);
  add(s.accel_ned_mps2);
  return v;
}

// The CSV prints 7 significant digits (%e): a decoded float agrees within 1e-6 relative.
void expect_row_matches(const std::vector<double>& decoded, const std::vector<double>& reference, std::size_t frame) {
  ASSERT_EQ(reference.size(), decoded.size()) << "frame " << frame;
  for (std::size_t i = 0; i < decoded.size(); ++i) {
    EXPECT_LE(std::abs(decoded[i] - reference[i]), 1e-6 * std::abs(reference[i]) + 1e-30)
        << "frame " << frame << " column " << i << ": " << decoded[i] << " vs " << reference[i];
  }
}

struct VnLog {
  const char* raw;
  const char* frames_only;
  const char* csv;
  std::uint64_t frames;
  std::uint64_t non_vn_bytes;      // README: bytes outside the CRC-valid frames of the raw file
  std::uint64_t crc_failures;      // README: candidates in the raw file that fail their CRC
  std::int64_t frame_without_row;  // the frame the author's parser skipped (−1: none)
  std::size_t junk_rows;           // leading CSV rows that are not frames
};

void PrintTo(const VnLog& log, std::ostream* os) {
  *os << log.raw;
}

const VnLog kF00294{"vectornav/LoggerWavesInIce_F00294.raw",
                    "vectornav/LoggerWavesInIce_F00294.frames_only.DERIVED.bin",
                    "vectornav/LoggerWavesInIce_F00294_B.reference.csv",
                    99,
                    2767,
                    0,
                    78,
                    0};
const VnLog kF00379{"vectornav/LoggerWavesInIce_F00379.raw",
                    "vectornav/LoggerWavesInIce_F00379.frames_only.DERIVED.bin",
                    "vectornav/LoggerWavesInIce_F00379_B.reference.csv",
                    8895,
                    334515,
                    2,
                    -1,
                    1};

class VnCapture : public ::testing::TestWithParam<VnLog> {};

TEST_P(VnCapture, RawStreamGivesEveryCrcValidFrameAndCountsTheRest) {
  const VnLog& log = GetParam();
  TRAJROI_REQUIRE_DATA(raw_path, log.raw);
  TRAJROI_REQUIRE_DATA(clean_path, log.frames_only);
  const Parsed raw = parse(as_bytes(test::read_file(raw_path)));
  EXPECT_EQ(raw.counters.frames, log.frames);
  EXPECT_EQ(raw.counters.skipped_bytes, log.non_vn_bytes);
  EXPECT_EQ(raw.counters.checksum_errors, log.crc_failures);
  // The frames found in the dirty stream are, byte for byte, the README's clean stream.
  const std::string clean = test::read_file(clean_path);
  std::string concatenated;
  for (const auto& f : raw.frames)
    concatenated.append(reinterpret_cast<const char*>(f.data()), f.size());
  EXPECT_TRUE(concatenated == clean);
  // Every frame has the logger's configuration: groups IMU + Attitude, 124 bytes.
  for (const auto& f : raw.frames) {
    ASSERT_EQ(f.size(), 124U);
    EXPECT_EQ(f[1], 0x14);
  }
}

TEST_P(VnCapture, FramesOnlyStreamHasNoSkippedByte) {
  const VnLog& log = GetParam();
  TRAJROI_REQUIRE_DATA(clean_path, log.frames_only);
  const Parsed clean = parse(as_bytes(test::read_file(clean_path)));
  EXPECT_EQ(clean.counters.frames, log.frames);
  EXPECT_EQ(clean.counters.skipped_bytes, 0U);
  EXPECT_EQ(clean.counters.checksum_errors, 0U);
}

TEST_P(VnCapture, ByteByByteGivesTheSameFrames) {
  const VnLog& log = GetParam();
  TRAJROI_REQUIRE_DATA(raw_path, log.raw);
  const std::string bytes = test::read_file(raw_path);
  const Parsed whole = parse(as_bytes(bytes));
  const Parsed single = parse(as_bytes(bytes), 1);
  EXPECT_EQ(single.frames, whole.frames);
  EXPECT_EQ(single.counters.skipped_bytes, whole.counters.skipped_bytes);
  EXPECT_EQ(single.counters.checksum_errors, whole.counters.checksum_errors);
}

TEST_P(VnCapture, DecodedValuesEqualTheAuthorsCsv) {
  const VnLog& log = GetParam();
  TRAJROI_REQUIRE_DATA(raw_path, log.raw);
  TRAJROI_REQUIRE_DATA(csv_path, log.csv);
  const Parsed raw = parse(as_bytes(test::read_file(raw_path)));
  const auto rows = test::read_numeric_csv(test::read_file(csv_path));
  ASSERT_EQ(rows.size() + (log.frame_without_row >= 0 ? 1 : 0), raw.samples.size() + log.junk_rows);
  std::size_t row = log.junk_rows;
  for (std::size_t frame = 0; frame < raw.samples.size(); ++frame) {
    if (static_cast<std::int64_t>(frame) == log.frame_without_row) continue;
    expect_row_matches(csv_order(raw.samples[frame]), rows[row++], frame);
    if (HasFailure()) return;  // one frame's report is enough
  }
  EXPECT_EQ(row, rows.size());
}

INSTANTIATE_TEST_SUITE_P(Logs, VnCapture, ::testing::Values(kF00294, kF00379),
                         [](const ::testing::TestParamInfo<VnLog>& param) {
                           return param.index == 0 ? std::string("F00294") : std::string("F00379");
                         });

TEST(VnCaptureF00294, FirstFrameEqualsTheReadmeValues) {
  TRAJROI_REQUIRE_DATA(path, kF00294.frames_only);
  const Parsed p = parse(as_bytes(test::read_file(path)));
  ASSERT_FALSE(p.samples.empty());
  const Sample& s = p.samples.front();
  EXPECT_TRUE(s.has(Field::kYawPitchRoll));
  EXPECT_FALSE(s.has(Field::kTimeStartup));  // the logger selected no time field
  EXPECT_NEAR(s.ypr_deg[0], 135.9274, 5e-5);
  EXPECT_NEAR(s.ypr_deg[1], -7.078407, 5e-7);
  EXPECT_NEAR(s.ypr_deg[2], 14.22944, 5e-6);
  EXPECT_NEAR(s.uncomp_accel_mps2[2], -9.384514, 5e-7);
  EXPECT_NEAR(s.temperature_c, 19.45568, 5e-6);
  EXPECT_NEAR(s.pressure_kpa, 102.088, 5e-4);
  // The DCM is a rotation: rows of unit length.
  for (int r = 0; r < 3; ++r) {
    double n = 0;
    for (int c = 0; c < 3; ++c)
      n += static_cast<double>(s.dcm[static_cast<std::size_t>(3 * r + c)]) *
           static_cast<double>(s.dcm[static_cast<std::size_t>(3 * r + c)]);
    EXPECT_NEAR(n, 1.0, 1e-5);
  }
}

}  // namespace
}  // namespace trajroi::vn100
