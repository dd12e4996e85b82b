// `trajroi export` read back by independent readers: a replay of the corridor through trajroid
// logged by liblcm (the file:// URL: lcm-logger's format), the log read here with liblcm's own
// reader (lcm::LogFile) for the expected clouds, and every exported file opened by PCL's tools
// (pcl_convert_pcd_ascii_binary, pcl_ply2pcd; Debian pcl-tools) and by Open3D (python3-open3d):
// the same points, field by field. A cut log is exported up to the cut, which is named.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "trajroi/points_t.hpp"

namespace {

namespace fs = std::filesystem;

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool have(const char* program) {
  return run(std::string("command -v ") + program + " >/dev/null 2>&1") == 0;
}

bool running_in_ci() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

#define REQUIRE_READER(available, what)                                                               \
  if (!(available)) {                                                                                 \
    if (running_in_ci()) FAIL() << what << " missing under CI (scripts/install-deps.sh installs it)"; \
    GTEST_SKIP() << what << " not installed (scripts/install-deps.sh installs it)";                   \
  }

// The corridor replayed through trajroid into an LCM log, and the log's clouds by sweep index.
struct Logged {
  fs::path dir, log;
  std::map<std::int64_t, trajroi::points_t> sweeps;
  Logged() {
    dir = fs::temp_directory_path() / ("trajroi_export_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    log = dir / "run.lcmlog";
    const fs::path run_dir = dir / "run";
    if (run(std::string(TRAJROI_CLI) + " sim --quiet --scenario " + TRAJROI_TEST_SCENARIO + " --out " +
            run_dir.string() + " >/dev/null") != 0 ||
        run(std::string(TRAJROID) + " --config " + (run_dir / "trajroid.yaml").string() + " --replay " +
            run_dir.string() + " --rate max --lcm-url 'file://" + log.string() + "?mode=w' 2>" +
            (dir / "trajroid.log").string()) != 0) {
      throw std::runtime_error("cannot make the test log: " + slurp(dir / "trajroid.log"));
    }
    lcm::LogFile file(log.string(), "r");
    while (const lcm::LogEvent* e = file.readNextEvent()) {
      if (e->channel != "TRAJROI_POINTS") continue;
      trajroi::points_t m;
      if (m.decode(e->data, 0, static_cast<int>(e->datalen)) == static_cast<int>(e->datalen)) sweeps[m.sweep_index] = m;
    }
  }
  ~Logged() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
};

const Logged& logged() {
  static const Logged l;
  return l;
}

// x y z intensity ring time return_type of each point, as PCL writes them in an ASCII PCD.
std::vector<std::vector<double>> pcl_ascii(const fs::path& pcd, const fs::path& scratch) {
  const fs::path ascii = scratch / (pcd.stem().string() + "_ascii.pcd");
  EXPECT_EQ(run("pcl_convert_pcd_ascii_binary " + pcd.string() + " " + ascii.string() + " 0 >/dev/null 2>&1"), 0)
      << pcd;
  std::istringstream in(slurp(ascii));
  std::vector<std::vector<double>> rows;
  bool data = false;
  for (std::string line; std::getline(in, line);) {
    if (!data) {
      data = line.rfind("DATA ascii", 0) == 0;
      continue;
    }
    std::istringstream fields(line);
    std::vector<double> row;
    for (double v; fields >> v;)
      row.push_back(v);
    if (!row.empty()) rows.push_back(row);
  }
  return rows;
}

void expect_same(const std::vector<std::vector<double>>& rows, const trajroi::points_t& m, const std::string& what) {
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(m.num_points)) << what;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 7U) << what;
    // PCL prints floats to 8 significant digits: within float rounding of the message's.
    EXPECT_NEAR(rows[i][0], static_cast<double>(m.x[i]), 1e-5 * (1.0 + std::abs(static_cast<double>(m.x[i]))))
        << what << " point " << i;
    EXPECT_NEAR(rows[i][1], static_cast<double>(m.y[i]), 1e-5 * (1.0 + std::abs(static_cast<double>(m.y[i]))))
        << what << " point " << i;
    EXPECT_NEAR(rows[i][2], static_cast<double>(m.z[i]), 1e-5 * (1.0 + std::abs(static_cast<double>(m.z[i]))))
        << what << " point " << i;
    EXPECT_EQ(rows[i][3], static_cast<double>(m.intensity[i])) << what << " point " << i;
    EXPECT_EQ(rows[i][4], static_cast<double>(m.ring[i])) << what << " point " << i;
    EXPECT_NEAR(rows[i][5], static_cast<double>(m.time_offset_ns[i]) * 1e-9, 1e-7) << what << " point " << i;
    EXPECT_EQ(rows[i][6], static_cast<double>(m.return_type[i])) << what << " point " << i;
  }
}

// Three sweeps across the run.
std::vector<std::int64_t> sample_sweeps() {
  const auto& s = logged().sweeps;
  std::vector<std::int64_t> out;
  for (const double at : {0.1, 0.5, 0.9}) {
    auto it = s.begin();
    std::advance(it, static_cast<std::ptrdiff_t>(at * static_cast<double>(s.size() - 1)));
    out.push_back(it->first);
  }
  return out;
}

std::string file_name(std::int64_t index, const char* extension) {
  char name[48];
  std::snprintf(name, sizeof name, "sweep_%06lld.%s", static_cast<long long>(index), extension);
  return name;
}

TEST(Export, PcdBinaryAndCompressedAndPlyAreReadBackByPcl) {
  REQUIRE_READER(have("pcl_convert_pcd_ascii_binary") && have("pcl_ply2pcd"), "PCL's tools (pcl-tools)");
  const Logged& l = logged();
  ASSERT_GT(l.sweeps.size(), 200U);
  const fs::path out = l.dir / "pcl";
  for (const char* kind : {"binary", "binary_compressed"}) {
    const fs::path dir = out / kind;
    ASSERT_EQ(run(std::string(TRAJROI_CLI) + " export " + l.log.string() + " --format pcd --pcd-data " + kind +
                  " --out " + dir.string() + " --quiet >" + (out.string() + kind + ".txt") + " 2>&1"),
              0)
        << slurp(out.string() + kind + ".txt");
    EXPECT_EQ(static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator())),
              l.sweeps.size());
    for (const std::int64_t index : sample_sweeps())
      expect_same(pcl_ascii(dir / file_name(index, "pcd"), out), l.sweeps.at(index),
                  std::string(kind) + " sweep " + std::to_string(index));
  }
  const fs::path ply = out / "ply";
  ASSERT_EQ(run(std::string(TRAJROI_CLI) + " export " + l.log.string() + " --format ply --out " + ply.string() +
                " --quiet >/dev/null"),
            0);
  for (const std::int64_t index : sample_sweeps()) {
    const fs::path converted = out / ("from_ply_" + std::to_string(index) + ".pcd");
    ASSERT_EQ(run("pcl_ply2pcd -format 1 " + (ply / file_name(index, "ply")).string() + " " + converted.string() +
                  " >/dev/null 2>&1"),
              0);
    expect_same(pcl_ascii(converted, out), l.sweeps.at(index), "ply sweep " + std::to_string(index));
  }
}

TEST(Export, PcdAndPlyAreReadBackByOpen3d) {
  REQUIRE_READER(run("/usr/bin/python3 -c 'import open3d' >/dev/null 2>&1") == 0, "Open3D (python3-open3d)");
  const Logged& l = logged();
  const fs::path out = l.dir / "open3d";
  ASSERT_EQ(run(std::string(TRAJROI_CLI) + " export " + l.log.string() +
                " --format pcd --pcd-data binary_compressed --out " + (out / "pcd").string() + " --quiet >/dev/null"),
            0);
  ASSERT_EQ(run(std::string(TRAJROI_CLI) + " export " + l.log.string() + " --format ply --out " +
                (out / "ply").string() + " --quiet >/dev/null"),
            0);
  // Open3D prints each cloud's points, one "x y z" line each, after a "# file count" line.
  const fs::path script = out / "read.py";
  std::ofstream(script) << "import sys\nimport numpy\nimport open3d\n"
                           "for path in sys.argv[1:]:\n"
                           "    points = numpy.asarray(open3d.io.read_point_cloud(path).points)\n"
                           "    print('#', path, len(points))\n"
                           "    numpy.savetxt(sys.stdout, points, fmt='%.9g')\n";
  for (const std::int64_t index : sample_sweeps()) {
    for (const auto& [folder, extension] : {std::pair{"pcd", "pcd"}, std::pair{"ply", "ply"}}) {
      const fs::path file = out / folder / file_name(index, extension);
      const fs::path text = out / (std::string(folder) + std::to_string(index) + ".txt");
      ASSERT_EQ(run("/usr/bin/python3 " + script.string() + " " + file.string() + " >" + text.string() + " 2>&1"), 0)
          << slurp(text);
      std::istringstream in(slurp(text));
      std::string hash, path;
      std::size_t count = 0;
      in >> hash >> path >> count;
      const trajroi::points_t& m = l.sweeps.at(index);
      ASSERT_EQ(count, static_cast<std::size_t>(m.num_points)) << file << "\n" << slurp(text).substr(0, 400);
      for (std::size_t i = 0; i < count; ++i) {
        double x = 0, y = 0, z = 0;
        in >> x >> y >> z;
        // 9 significant digits give a float back exactly.
        ASSERT_EQ(static_cast<float>(x), m.x[i]) << file << " point " << i;
        ASSERT_EQ(static_cast<float>(y), m.y[i]) << file << " point " << i;
        ASSERT_EQ(static_cast<float>(z), m.z[i]) << file << " point " << i;
      }
    }
  }
}

TEST(Export, AnAccumulatedMapHoldsEverySweepsPointsOrOnePerVoxel) {
  REQUIRE_READER(have("pcl_convert_pcd_ascii_binary"), "PCL's tools (pcl-tools)");
  const Logged& l = logged();
  std::size_t total = 0;
  for (const auto& [index, m] : l.sweeps)
    total += static_cast<std::size_t>(m.num_points);
  const fs::path out = l.dir / "map";
  ASSERT_EQ(run(std::string(TRAJROI_CLI) + " export " + l.log.string() + " --accumulate --out " +
                (out / "all").string() + " --quiet >/dev/null"),
            0);
  EXPECT_EQ(pcl_ascii(out / "all" / "map.pcd", out).size(), total);
  ASSERT_EQ(run(std::string(TRAJROI_CLI) + " export " + l.log.string() + " --accumulate --voxel 0.5 --out " +
                (out / "thin").string() + " --quiet >/dev/null"),
            0);
  const auto thin = pcl_ascii(out / "thin" / "map.pcd", out);
  EXPECT_LT(thin.size(), total / 4);
  // One point per 0.5 m cube: no two in the same one.
  std::set<std::tuple<long, long, long>> cells;
  for (const auto& p : thin)
    cells.insert({std::lround(std::floor(p[0] / 0.5)), std::lround(std::floor(p[1] / 0.5)),
                  std::lround(std::floor(p[2] / 0.5))});
  EXPECT_GE(cells.size() + thin.size() / 1000, thin.size());  // float printing may move a point on a face
}

TEST(Export, ACutLogIsExportedUpToTheCutWhichIsNamed) {
  const Logged& l = logged();
  const fs::path cut = l.dir / "cut.lcmlog";
  {
    const std::string bytes = slurp(l.log);
    std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  const fs::path out = l.dir / "cut";
  const fs::path said = l.dir / "cut.txt";
  EXPECT_EQ(run(std::string(TRAJROI_CLI) + " export " + cut.string() + " --out " + out.string() + " --quiet >" +
                said.string() + " 2>&1"),
            1);
  const std::string text = slurp(said);
  EXPECT_NE(text.find(cut.string() + ": cut short: its last event, from byte "), std::string::npos) << text;
  const auto files = static_cast<std::size_t>(std::distance(fs::directory_iterator(out), fs::directory_iterator()));
  EXPECT_GT(files, l.sweeps.size() / 3);
  EXPECT_NE(text.find("the " + std::to_string(files) + " sweeps before it are exported"), std::string::npos) << text;
  // An output folder that cannot be made is named.
  EXPECT_EQ(run(std::string(TRAJROI_CLI) + " export " + l.log.string() + " --out /proc/trajroi_export --quiet >" +
                said.string() + " 2>&1"),
            1);
  EXPECT_NE(slurp(said).find("/proc/trajroi_export: cannot create the output folder"), std::string::npos)
      << slurp(said);
}

}  // namespace
