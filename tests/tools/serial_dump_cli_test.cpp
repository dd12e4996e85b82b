// `trajroi gnss-dump` and `trajroi imu-dump` on every real log, against the independent
// references: gpsd's .chk (printed text compared as text) and the VN-100 author's CSV.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.hpp"
#include "gpsd_chk.hpp"
#include "numeric_csv.hpp"
#include "test_data.hpp"
#include "trajroi/serial/byte_log.hpp"

namespace {

// The value of `"key": ` in one JSON line of ours, as printed.
std::string field(const std::string& line, const std::string& key) {
  std::string pattern = "\"";
  pattern.append(key).append("\": ");
  const std::size_t at = line.find(pattern);
  if (at == std::string::npos) return {};
  const std::size_t begin = at + pattern.size();
  std::size_t end = line.find_first_of(",}", begin);
  std::string v = line.substr(begin, end - begin);
  if (!v.empty() && v.front() == '"') v = v.substr(1, v.size() - 2);
  return v;
}

// gpsd's printed lat/lon of each TPV time.
std::multimap<std::string, std::pair<std::string, std::string>> gpsd_positions(const std::string& chk) {
  std::multimap<std::string, std::pair<std::string, std::string>> out;
  std::istringstream in(chk);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("{\"class\":\"TPV\"", 0) != 0) continue;
    std::string lat = trajroi::test::json_raw(line, "lat");
    if (!lat.empty())
      out.emplace(trajroi::test::json_raw(line, "time"), std::make_pair(lat, trajroi::test::json_raw(line, "lon")));
  }
  return out;
}

struct GnssCase {
  const char* file;
  std::size_t fixes;
  std::size_t equal_to_gpsd;  // fixes whose printed lat and lon equal gpsd's text for that time
  const char* frames_json;    // the "frames" object we print, checked against the README counts
};

class GnssDumpCli : public Cli, public ::testing::WithParamInterface<GnssCase> {};

TEST_P(GnssDumpCli, JsonFixesEqualGpsdText) {
  const GnssCase& c = GetParam();
  TRAJROI_REQUIRE_DATA(log, c.file);
  std::string chk_name = c.file;
  chk_name += ".chk";
  TRAJROI_REQUIRE_DATA(chk, chk_name);
  const CommandResult r = run("gnss-dump --json " + log.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"checksum_errors\": 0,"), std::string::npos);
  if (c.frames_json != nullptr) {
    EXPECT_NE(r.out.find(c.frames_json), std::string::npos) << r.out.substr(0, 600);
  }
  const auto gpsd = gpsd_positions(trajroi::test::read_file(chk));
  std::size_t fixes = 0;
  std::size_t equal = 0;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);) {
    if (line.find("\"utc\": ") == std::string::npos) continue;
    ++fixes;
    const auto [first, last] = gpsd.equal_range(field(line, "utc"));
    for (auto it = first; it != last; ++it) {
      if (it->second.first == field(line, "lat") && it->second.second == field(line, "lon")) {
        ++equal;
        break;
      }
    }
  }
  EXPECT_EQ(fixes, c.fixes);
  EXPECT_EQ(equal, c.equal_to_gpsd);
}

// Equal counts are those of the library test (tests/ublox/capture_test.cpp), where each
// exception is explained; gpsd's zed-f9p-hp and zed-f9r positions come from NAV-HPPOSLLH and
// NMEA, which NAV-PVT's 1e-7° cannot print identically.
INSTANTIATE_TEST_SUITE_P(Logs, GnssDumpCli,
                         ::testing::Values(GnssCase{"ublox/gpsd/ublox-neo-m8n.log", 24, 22,
                                                    R"({"NAV-PVT": 24, "NAV-TIMEGPS": 23, "NAV-SAT": 5})"},
                                           GnssCase{"ublox/gpsd/ublox-glo.log", 299, 291, nullptr},
                                           GnssCase{"ublox/gpsd/ublox-neo-m8l.log", 19, 17, nullptr},
                                           GnssCase{"ublox/gpsd/ublox-neo-m8p.log", 59, 58, nullptr},
                                           GnssCase{"ublox/gpsd/ublox-zed-f9t-rtcm3.log", 26, 22, nullptr},
                                           GnssCase{"ublox/gpsd/ublox8-uniqid-monhw.log", 7, 6, nullptr},
                                           GnssCase{"ublox/gpsd/ublox-zed-f9p-hp.log", 29, 0, nullptr},
                                           GnssCase{"ublox/gpsd/ublox-zed-f9r.log", 30, 0, nullptr}),
                         [](const ::testing::TestParamInfo<GnssCase>& p) { return "log" + std::to_string(p.index); });

TEST_F(Cli, GnssDumpOfPyubx2LogsPrintsTheirFixes) {
  TRAJROI_REQUIRE_DATA(nav, "ublox/pyubx2/pygpsdata-NAV.log");
  const CommandResult r = run("gnss-dump --json " + nav.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // pyubx2's own test expects this NAV-PVT: 2021-12-04 11:34:59, lat 53.4507228, lon −2.2402855.
  EXPECT_NE(r.out.find("\"utc\": \"2021-12-04T11:34:59.000Z\""), std::string::npos) << r.out;
  EXPECT_NE(
      r.out.find(
          "\"lat\": 53.450722800, \"lon\": -2.240285500, \"height_m\": 91.184, \"hmsl_m\": 42.701, \"h_acc_m\": 1.491"),
      std::string::npos);
}

// A run recorded as .trjb (chunks of any size, with times) dumps exactly as the raw log.
TEST_F(Cli, GnssDumpReadsRecordingsLikeRawLogs) {
  TRAJROI_REQUIRE_DATA(log, "ublox/gpsd/ublox-neo-m8p.log");
  const std::string bytes = trajroi::test::read_file(log);
  const fs::path recording = dir_ / "m8p.trjb";
  {
    trajroi::serial::RecordingWriter writer(recording.string());
    const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
    for (std::size_t at = 0, n = 1; at < bytes.size(); at += n, n = n % 97 + 1) {
      n = std::min(n, bytes.size() - at);
      writer.write({std::span<const std::uint8_t>(data + at, n), static_cast<std::int64_t>(at) * 1000});
    }
  }
  const CommandResult raw = run("gnss-dump --json " + log.string());
  const CommandResult rec = run("gnss-dump --json " + recording.string());
  ASSERT_EQ(raw.exit_code, 0) << raw.err;
  ASSERT_EQ(rec.exit_code, 0) << rec.err;
  // Identical apart from the file name.
  EXPECT_EQ(raw.out.substr(raw.out.find("\"bytes\"")), rec.out.substr(rec.out.find("\"bytes\"")));
}

TEST_F(Cli, DumpsNameAMissingFile) {
  const CommandResult r = run("gnss-dump /nonexistent/gnss.ubx");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("/nonexistent/gnss.ubx"), std::string::npos) << r.err;
}

TEST_F(Cli, GarbageIsCountedNotFatal) {
  std::string garbage(5000, 'x');
  garbage[100] = static_cast<char>(0xB5);
  garbage[101] = 0x62;
  garbage[4000] = static_cast<char>(0xFA);
  const fs::path p = write("garbage.bin", garbage);
  const CommandResult g = run("gnss-dump --json " + p.string());
  ASSERT_EQ(g.exit_code, 0) << g.err;
  EXPECT_NE(g.out.find("\"skipped_bytes\": 5000"), std::string::npos) << g.out;
  EXPECT_NE(g.out.find("\"fixes\": []"), std::string::npos) << g.out;
  const CommandResult i = run("imu-dump --csv " + p.string());
  ASSERT_EQ(i.exit_code, 0) << i.err;
  EXPECT_EQ(i.out.substr(0, i.out.find('\n')), "yaw_deg,pitch_deg,roll_deg,accel_x,accel_y,accel_z");
}

struct ImuCase {
  const char* raw;
  const char* csv;
  std::size_t rows;
  long skipped_frame;  // the frame the author's parser missed (−1: none)
  std::size_t junk_rows;
};

class ImuDumpCli : public Cli, public ::testing::WithParamInterface<ImuCase> {};

TEST_P(ImuDumpCli, CsvEqualsTheAuthorsCsv) {
  const ImuCase& c = GetParam();
  TRAJROI_REQUIRE_DATA(raw, c.raw);
  TRAJROI_REQUIRE_DATA(reference, c.csv);
  const CommandResult r = run("imu-dump --csv " + raw.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> ours_header;
  const auto ours = trajroi::test::read_numeric_csv(r.out, &ours_header);
  const auto theirs = trajroi::test::read_numeric_csv(trajroi::test::read_file(reference));
  ASSERT_EQ(ours.size(), c.rows);
  // The author's columns, in order, and ours holding the same quantity.
  const std::vector<std::string> mapping{
      "mag_x",     "mag_y",     "mag_z",       "accel_x",     "accel_y",    "accel_z",  "gyro_x", "gyro_y",
      "gyro_z",    "temp_c",    "pres_kpa",    "yaw_deg",     "pitch_deg",  "roll_deg", "dcm_1",  "dcm_2",
      "dcm_3",     "dcm_4",     "dcm_5",       "dcm_6",       "dcm_7",      "dcm_8",    "dcm_9",  "mag_ned_n",
      "mag_ned_e", "mag_ned_d", "accel_ned_n", "accel_ned_e", "accel_ned_d"};
  std::vector<std::size_t> index;
  for (const std::string& name : mapping) {
    const auto it = std::find(ours_header.begin(), ours_header.end(), name);
    ASSERT_NE(it, ours_header.end()) << name;
    index.push_back(static_cast<std::size_t>(it - ours_header.begin()));
  }
  std::size_t row = c.junk_rows;
  for (std::size_t frame = 0; frame < ours.size(); ++frame) {
    if (static_cast<long>(frame) == c.skipped_frame) continue;
    ASSERT_LT(row, theirs.size());
    for (std::size_t k = 0; k < mapping.size(); ++k) {
      const double a = ours[frame][index[k]];
      const double b = theirs[row][k];
      ASSERT_LE(std::abs(a - b), 1e-6 * std::abs(b) + 1e-30) << "frame " << frame << " " << mapping[k];
    }
    ++row;
  }
  EXPECT_EQ(row, theirs.size());
}

INSTANTIATE_TEST_SUITE_P(Logs, ImuDumpCli,
                         ::testing::Values(ImuCase{"vectornav/LoggerWavesInIce_F00294.raw",
                                                   "vectornav/LoggerWavesInIce_F00294_B.reference.csv", 99, 78, 0},
                                           ImuCase{"vectornav/LoggerWavesInIce_F00379.raw",
                                                   "vectornav/LoggerWavesInIce_F00379_B.reference.csv", 8895, -1, 1}),
                         [](const ::testing::TestParamInfo<ImuCase>& p) {
                           return p.index == 0 ? std::string("F00294") : std::string("F00379");
                         });

}  // namespace
