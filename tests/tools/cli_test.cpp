// The `trajroi` binary run as a user runs it: real files, real exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_fixture.hpp"
#include "test_data.hpp"

namespace {

TEST_F(Cli, VersionIsPrinted) {
  const CommandResult r = run("--version");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "trajroi " TRAJROI_VERSION "\n");
}

TEST_F(Cli, FilterAppliesThePoseAndKeepsTheRightIndices) {
  const fs::path traj = write("t.csv", "# straight 10 m\n0,0\n10,0\n");
  // Robot at (5, 0) facing +y (yaw 90°): sensor (2,0) → global (5,2); (0,−4) → (9,0);
  // (0,9) → (−4,0); (0,−8) → (13,0), exactly r = 3 m past the last centre: inside,
  // the test is inclusive; (7,0) → (5,7).
  const fs::path pts = write("p.csv", "2,0,0\n0,-4,0,10\n0,9,0\n0,-8,0\n7,0,0\nnan,0,0\n");
  const fs::path out = dir_ / "kept.txt";
  for (const char* algorithm : {"reference", "fast"}) {
    const CommandResult r = run("filter --trajectory " + traj.string() + " --points " + pts.string() +
                                " --shape circular --diameter 6 --spacing 1 --pose 5,0,90 --algorithm " + algorithm +
                                " --output-indices " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(slurp(out), "0\n1\n3\n") << algorithm;
    EXPECT_NE(r.err.find("1 non-finite"), std::string::npos) << r.err;
  }
}

TEST_F(Cli, FilterRectangleCorridorAndCuboid) {
  const fs::path traj = write("t.csv", "0,0\n10,0\n10,10\n");
  const fs::path pts = write("p.csv", "5,0.9,0\n5,1.1,0\n11.2,5,0\n-0.4,0,0\n10.9,10.9,0\n");
  const fs::path out = dir_ / "kept.txt";
  CommandResult r =
      run("filter --trajectory " + traj.string() + " --points " + pts.string() +
          " --shape rectangular --height 1 --width 2 --spacing-ratio 0.5 --output-indices " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(out), "0\n3\n");  // (11.2,5) is 1.2 m across, (10.9,10.9) 0.9 m past the end (a/2 = 0.5)
  r = run("filter --trajectory " + traj.string() + " --points " + pts.string() +
          " --shape corridor --width 2.6 --output-indices " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(out), "0\n1\n2\n3\n4\n");  // (10.9,10.9): 1.27 m from the end (round cap, 1.3)
  r = run("filter --trajectory " + traj.string() + " --points " + pts.string() +
          " --shape cuboid --length 12 --width 2 --z-min -1 --z-max 1 --output-indices " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(out), "0\n3\n");
}

TEST_F(Cli, MalformedPointsNameFileAndLineAndWriteNothing) {
  const fs::path traj = write("t.csv", "0,0\n10,0\n");
  const fs::path pts = write("p.csv", "1,0,0\n2,0,0\n3,zero,0\n");
  const fs::path out = dir_ / "kept.txt";
  const CommandResult r = run("filter --trajectory " + traj.string() + " --points " + pts.string() +
                              " --shape circular --diameter 6 --spacing 1 --output-indices " + out.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(pts.string() + ":3:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, BadTrajectoryAndBadSizesAreClearErrors) {
  const fs::path pts = write("p.csv", "1,0,0\n");
  const fs::path out = dir_ / "kept.txt";
  struct Case {
    std::string traj;
    std::string args;
    std::string expected;
  };
  for (const Case& c :
       {Case{"0,0\n0,0\n", "--shape circular --diameter 6 --spacing 1", "at least two distinct"},
        Case{"0,0\n1,x\n", "--shape circular --diameter 6 --spacing 1", "t.csv:2:"},
        Case{"0,0\n9,0\n", "--shape circular --diameter -6 --spacing 1", "radius must be finite and positive"},
        Case{"0,0\n9,0\n", "--shape circular --diameter 6 --spacing 0", "spacing must be finite and positive"},
        Case{"0,0\n9,0\n", "--shape rectangular --height 0 --width 2 --spacing 1", "height a must be"},
        Case{"0,0\n9,0\n", "--shape rectangular --height 1 --width 2", "exactly one of --spacing"},
        Case{"0,0\n9,0\n", "--shape circular --spacing 1", "--diameter is required"},
        Case{"0,0\n9,0\n", "--shape circular --diameter 6 --spacing 1 --pose 1,2", "--pose expects"}}) {
    const fs::path traj = write("t.csv", c.traj);
    const CommandResult r = run("filter --trajectory " + traj.string() + " --points " + pts.string() + " " + c.args +
                                " --output-indices " + out.string());
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.args << " → " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

TEST_F(Cli, EvalArtificialCsvMatchesThePaper) {
  const CommandResult r = run("eval artificial --format csv --data straight --shape circular --reps 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line,
            "data,shape,ratio_pct,num_roi,tp,fp,fn,tn,precision,recall,accuracy,ref_min_ms,ref_max_ms,"
            "ref_avg_ms,fast_min_ms,fast_max_ms,fast_avg_ms");
  std::getline(lines, line);
  EXPECT_EQ(line.rfind("straight,circular,150,10,6234,0,6197,8020,1.000000,0.501488,0.696983,", 0), 0u) << line;
  int rows = 1;
  while (std::getline(lines, line))
    ++rows;
  EXPECT_EQ(rows, 7);
}

TEST_F(Cli, EvalArtificialWritesSvgPictures) {
  const CommandResult r =
      run("eval artificial --data curved --shape rectangular --reps 1 --svg " + (dir_ / "svg").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string svg = slurp(dir_ / "svg" / "curved_rectangular_010.svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("272 ROIs — TP 11803, FP 49"), std::string::npos);
  EXPECT_NE(svg.find("<polygon"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

// lidar-dump on the real captures: the figures the data README gives (from its own walker)
// and the GPRMC sentence of the MRPT capture.
TEST_F(Cli, LidarDumpReportsTheMrptCapture) {
  TRAJROI_REQUIRE_DATA(capture, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const fs::path points = dir_ / "points.csv";
  const CommandResult r = run("lidar-dump --json " + capture.string() + " --points " + points.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* field : {"\"data_packets\": 293,", "\"position_packets\": 57,", "\"unsupported_product\": 0}",
                            "\"model\": \"VLP-16\"", "\"product_id\": \"0x22\"", "\"return_mode\": \"strongest\"",
                            "\"frames\": 3,", "\"partial_frames\": 2,", "\"points\": 73486,", "\"lost_packets\": 0,",
                            "\"first\": {\"utc\": \"2016-01-21T08:18:02.000Z\", \"valid\": true, \"lat\": "
                            "36.829130930, \"lon\": -2.407571547}"}) {
    EXPECT_NE(r.out.find(field), std::string::npos) << field << " not in " << r.out;
  }
  const std::string csv = slurp(points);
  EXPECT_EQ(csv.rfind("frame,x,y,z,intensity,ring,azimuth_deg,distance_m,time_ns,return_type\n", 0), 0u);
  std::size_t rows = 0;
  for (const char c : csv)
    rows += c == '\n' ? 1 : 0;
  EXPECT_EQ(rows, 73486u + 1u);
  EXPECT_FALSE(fs::exists(dir_ / "points.csv.partial"));
}

TEST_F(Cli, LidarDumpNamesTheRejectedModel) {
  TRAJROI_REQUIRE_DATA(capture, "velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap");
  const CommandResult r = run("lidar-dump --model vlp16 --json " + capture.string());
  // The report, then a failure that says nothing could be decoded.
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("no data packet could be decoded: all 500 data packets rejected: product id 0x21 "
                       "(HDL-32E) sends HDL-32E packets (told by its timing: 553 µs between packets), but "
                       "lidar.model is vlp16"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("\"unsupported_product\": 500}"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"model\": \"HDL-32E\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"points\": 0,"), std::string::npos) << r.out;
}

// Without --model the model is the packets': the HDL-32E capture decodes, and says so.
TEST_F(Cli, LidarDumpReportsTheModelItFound) {
  TRAJROI_REQUIRE_DATA(hdl32e, "velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap");
  TRAJROI_REQUIRE_DATA(vlp32c, "velodyne/other_models/nebula_vlp32c_strongest_1713492677.DERIVED.pcap");
  const CommandResult a = run("lidar-dump " + hdl32e.string());
  EXPECT_EQ(a.exit_code, 0) << a.err;
  EXPECT_NE(a.out.find("model             HDL-32E (product id 0x21)"), std::string::npos) << a.out;
  EXPECT_NE(a.out.find("500 decoded, 0 rejected"), std::string::npos) << a.out;
  const CommandResult b = run("lidar-dump --json " + vlp32c.string());
  EXPECT_EQ(b.exit_code, 0) << b.err;
  EXPECT_NE(b.out.find("\"model\": \"VLP-32C\""), std::string::npos) << b.out;
}

TEST_F(Cli, LidarDumpOfATruncatedCaptureReportsWhatItReadThenFails) {
  TRAJROI_REQUIRE_DATA(capture, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const std::string bytes = trajroi::test::read_file(capture);
  const fs::path cut = write("cut.pcap", "");
  std::ofstream(cut, std::ios::binary).write(bytes.data(), 200'000);
  const CommandResult r = run("lidar-dump --json " + cut.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("\"read_error\": \""), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
}

TEST_F(Cli, LidarDumpRejectsAMissingFileAndABadCalibration) {
  CommandResult r = run("lidar-dump /nonexistent.pcap");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("/nonexistent.pcap"), std::string::npos) << r.err;
  const fs::path yaml = write("bad.yaml", "lasers:\n  - {laser_id: 0, vert_correction: 0.1}\n");
  const fs::path pcap = write("empty.pcap", "");
  r = run("lidar-dump " + pcap.string() + " --calibration " + yaml.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("'lasers' has 1 entries; the models trajroi decodes have 16"), std::string::npos) << r.err;
}

}  // namespace

// trajroi machine: one line per core with its pieces and spells, the machine's summary; the
// brief form three numbers; bad settings a clear error and exit code 2. (Whether this machine
// has slow spells is its own affair: only the form and the counts are checked.)
TEST_F(Cli, MachineReportsEveryCoreAndRefusesBadSettings) {
  const CommandResult r = run("machine --seconds 0.5 --every-ms 5 --piece-us 20 --priority 0");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("SCHED_OTHER"), std::string::npos) << r.out;
  const auto cores = static_cast<std::size_t>(sysconf(_SC_NPROCESSORS_ONLN));
  std::size_t lines = 0;
  for (std::size_t at = r.out.find("\ncpu "); at != std::string::npos; at = r.out.find("\ncpu ", at + 1))
    ++lines;
  EXPECT_GE(lines, 1U);
  EXPECT_LE(lines, cores);
  EXPECT_NE(r.out.find(" pieces, full speed "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("machine: longest slow spell "), std::string::npos) << r.out;

  const CommandResult brief = run("machine --seconds 0.3 --priority 0 --brief");
  ASSERT_EQ(brief.exit_code, 0) << brief.err;
  std::istringstream fields(brief.out);
  double longest_ms = -1.0;
  double worst = -1.0;
  double slow_ms = -1.0;
  ASSERT_TRUE(fields >> longest_ms >> worst >> slow_ms) << brief.out;
  EXPECT_GE(longest_ms, 0.0);
  EXPECT_LE(longest_ms, slow_ms + 1e-9);
  // A spell is over 2x full speed; printed to 0.01, one just over 2x reads 2.00.
  EXPECT_TRUE(worst == 0.0 || worst >= 2.0) << "a spell is over 2x full speed: " << brief.out;

  for (const char* bad : {"--seconds 0", "--every-ms -1", "--piece-us 6000 --every-ms 5"}) {
    const CommandResult b = run(std::string("machine ") + bad);
    EXPECT_EQ(b.exit_code, 2) << bad;
    EXPECT_NE(b.err.find("must be positive"), std::string::npos) << bad << ": " << b.err;
  }
}

namespace {

long rmem_max_bytes() {
  std::ifstream in("/proc/sys/net/core/rmem_max");
  long bytes = 0;
  in >> bytes;
  return bytes;
}

// trajroi watch asks for its receive buffer past net.core.rmem_max where it may (root:
// SO_RCVBUFFORCE) and says nothing; as an unprivileged user it says in one line how far the
// kernel capped it and how to raise the limit.
TEST_F(Cli, WatchTakesItsReceiveBufferOrSaysTheKernelCappedIt) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root (SO_RCVBUFFORCE, and setpriv to drop it)";
  const long max = rmem_max_bytes();
  ASSERT_GT(max, 0);
  const long ask = std::min(4 * max, 1L << 29);
  const std::string url = "'udpm://239.255.76.67:7667?ttl=0&recv_buf_size=" + std::to_string(ask) + "'";
  const CommandResult root = run("watch --seconds 0.3 --lcm-url " + url);
  EXPECT_EQ(root.exit_code, 0) << root.err;
  EXPECT_EQ(root.err.find("capped"), std::string::npos) << root.err;

  const fs::path err = dir_ / "nobody.txt";
  const std::string command = "setpriv --reuid=65534 --regid=65534 --clear-groups " + std::string(TRAJROI_CLI) +
                              " watch --seconds 0.3 --lcm-url " + url + " >/dev/null 2>" + err.string();
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << slurp(err);
  const std::string expected = "trajroi watch: the kernel capped the LCM receive buffer at " +
                               std::to_string(max / 1024) + " KiB of the " + std::to_string(ask / 1024) +
                               " KiB asked for";
  EXPECT_NE(slurp(err).find(expected), std::string::npos) << slurp(err);
  EXPECT_NE(slurp(err).find("60-trajroi-lcm.conf"), std::string::npos) << slurp(err);
}

}  // namespace
