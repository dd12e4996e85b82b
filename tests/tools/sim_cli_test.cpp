// trajroi sim, eval keyframes/sequential/accumulated and render, end to end through the
// binary: bad input is refused with nothing written, good input gives the tables.
#include "cli_fixture.hpp"

namespace {

const char* kScenario = R"(name: cli
start_utc: 2024-05-14T09:00:00Z
origin: {lat_deg: 36.3721, lon_deg: 127.3604, height_m: 60}
world:
  boxes:
    - {name: wall_n, centre: [0, 15], size: [40, 0.3], height: 4}
    - {name: wall_s, centre: [0, -15], size: [40, 0.3], height: 4}
trajectory: {start: [0, 0], heading_deg: 0, segments: [{line: 4}, {arc: {radius: 5, turn_deg: 45}}, {line: 3}]}
robot: {speed_mps: 2, wait_before_s: 1, wait_after_s: 0.5}
evaluation:
  circle_diameter_m: 10
  rect_height_m: 5
  rect_width_m: 10
  look_ahead_m: 6
  corridor_width_m: 10
  keyframes:
    - {name: kf_a, position: [1, 0], heading_rad: 0}
    - {name: kf_b, position: [4, 0], heading_rad: 0}
)";

TEST_F(Cli, SimRefusesABadScenarioAndWritesNothing) {
  std::string bad = kScenario;
  bad.replace(bad.find("speed_mps: 2"), 12, "speed_mps: -2");
  const fs::path scenario = write("bad.yaml", bad);
  const CommandResult r = run("sim --scenario " + scenario.string() + " --out " + (dir_ / "run").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("bad.yaml:9: robot.speed_mps: must be > 0 (got '-2')"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "run"));
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string().find(".run"), std::string::npos);
}

TEST_F(Cli, EvalArtificialSpeaksJsonToo) {
  const CommandResult r = run("eval artificial --data straight --shape circular --reps 1 --format json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(
      r.out.find("{\"reps\": 1, \"rows\": [\n  {\"data\": \"straight\", \"shape\": \"circular\", \"ratio_pct\": 150,"),
      0u)
      << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 9);  // 7 rows, the opening and the close
  EXPECT_EQ(r.out.find("\"fast_equals_reference\": false"), std::string::npos);
}

TEST_F(Cli, EvalOnAFolderThatIsNotARunIsAClearError) {
  fs::create_directories(dir_ / "empty");
  for (const char* sub : {"keyframes", "sequential", "accumulated"}) {
    const CommandResult r = run(std::string("eval ") + sub + " --scenario " + (dir_ / "empty").string());
    EXPECT_NE(r.exit_code, 0) << sub;
    EXPECT_NE(r.err.find("not a scenario run folder (no scenario.yaml"), std::string::npos) << r.err;
  }
  const CommandResult missing = run("eval keyframes --scenario " + (dir_ / "nowhere").string());
  EXPECT_NE(missing.err.find("nowhere: not a folder"), std::string::npos) << missing.err;
}

TEST_F(Cli, SimThenEveryEvaluationAndRender) {
  const fs::path scenario = write("cli.yaml", kScenario);
  const fs::path run_dir = dir_ / "run";
  const CommandResult sim = run("sim --quiet --scenario " + scenario.string() + " --out " + run_dir.string());
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_NE(sim.out.find("x real time"), std::string::npos);
  for (const char* file : {"scenario.yaml", "lidar.pcap", "gnss.trjb", "imu.trjb", "trajectory.csv", "trajroid.yaml",
                           "truth/poses.bin", "truth/labels.bin", "summary.txt"}) {
    EXPECT_TRUE(fs::is_regular_file(run_dir / file)) << file;
  }

  const CommandResult kf =
      run("eval keyframes --reps 3 --format csv --scenario " + run_dir.string() + " --svg " + (dir_ / "svg").string());
  ASSERT_EQ(kf.exit_code, 0) << kf.err;
  std::istringstream lines(kf.out);
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "keyframe,shape,ratio_pct,num_roi,tp,fp,fn,tn,precision,recall,accuracy,min_ms,max_ms,avg_ms");
  int rows = 0;
  for (std::string line; std::getline(lines, line);) {
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 13) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 2 * 2 * 4);  // keyframes × shapes × spacings
  EXPECT_TRUE(fs::is_regular_file(dir_ / "svg" / "kf_b_rectangular_025.svg"));

  const CommandResult json = run("eval keyframes --reps 1 --format json --scenario " + run_dir.string());
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_EQ(json.out.find("{\"scenario\": \"cli\""), 0u) << json.out;

  const CommandResult seq = run("eval sequential --scenario " + run_dir.string() + " --svg " + (dir_ / "svg").string());
  ASSERT_EQ(seq.exit_code, 0) << seq.err;
  EXPECT_NE(seq.out.find("point cloud cycle"), std::string::npos);
  EXPECT_TRUE(fs::is_regular_file(dir_ / "svg" / "sequential.svg"));
  const CommandResult seq_csv = run("eval sequential --format csv --scenario " + run_dir.string());
  EXPECT_EQ(seq_csv.out.find("series,frames,min_ms,max_ms,avg_ms\npoint_cloud_cycle,"), 0u) << seq_csv.out;

  const CommandResult acc = run("eval accumulated --format csv --scenario " + run_dir.string());
  ASSERT_EQ(acc.exit_code, 0) << acc.err;
  EXPECT_EQ(acc.out.find("shape,frames_per_cloud,clouds,avg_points,min_ms,max_ms,avg_ms\ncircular,1,"), 0u) << acc.out;

  const CommandResult render =
      run("render --scenario " + run_dir.string() + " --keyframe kf_b --out " + (dir_ / "kf_b.svg").string());
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const std::string svg = slurp(dir_ / "kf_b.svg");
  for (const char* panel : {"Raw point cloud", "Long cuboid ROI", "Circular ROI (25 %)", "Rectangular ROI (25 %)"}) {
    EXPECT_NE(svg.find(panel), std::string::npos) << panel;
  }
  EXPECT_NE(run("render --scenario " + run_dir.string() + " --keyframe nope --out x.svg")
                .err.find("no keyframe named 'nope'"),
            std::string::npos);
}

}  // namespace
