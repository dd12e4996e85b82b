// trajroi eval keyframes | sequential | accumulated, and trajroi render: the paper's Tables
// 9, 11, 18, 19 and 20 on a run folder written by `trajroi sim`.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "file_io.hpp"
#include "trajroi/eval/scenario_eval.hpp"
#include "trajroi/eval/svg.hpp"
#include "trajroi/roi/cuboid.hpp"

namespace trajroi::cli {
namespace {

namespace fs = std::filesystem;
constexpr int kKeyframeRatiosPct[] = {100, 75, 50, 25};

struct ScenarioEvalOptions {
  std::string scenario;
  std::string format = "table";
  std::string svg_dir;
  std::string pose = "per-firing";
  int reps = 3;  // keyframes: passes of the whole run (every row of a pass at once)
};

// "per-frame" is the older name of per-sweep (one pose for the whole sweep, the paper's way).
eval::PoseMode pose_mode(const std::string& name) {
  return name == "per-sweep" || name == "per-frame" ? eval::PoseMode::kPerSweep : eval::PoseMode::kPerFiring;
}

void add_common_options(CLI::App* cmd, ScenarioEvalOptions& o) {
  cmd->add_option("--scenario", o.scenario, "Run folder written by `trajroi sim`")->required();
  cmd->add_option("--format", o.format, "Output format")
      ->check(CLI::IsMember({"table", "csv", "json"}))
      ->capture_default_str();
  cmd->add_option("--svg", o.svg_dir, "Also write SVG pictures into this folder");
  cmd->add_option("--pose", o.pose, "Pose per firing sequence (motion-compensated) or one per sweep (the paper)")
      ->check(CLI::IsMember({"per-firing", "per-sweep", "per-frame"}))
      ->capture_default_str();
}

std::string shape_name(eval::RoiShape shape) {
  return std::string(eval::to_string(shape));
}

// The window of a frame's top-down pictures: the cloud's extent, clipped to 60 m around the
// robot (a 100 m range reaches far beyond what a person wants to look at).
struct Window {
  double x0, y0, x1, y1;
};
Window window_around(const Eigen::Vector3d& robot, double half_m) {
  return {robot.x() - half_m, robot.y() - half_m, robot.x() + half_m, robot.y() + half_m};
}

std::vector<Eigen::Vector2d> xy_of(const std::vector<roi::PointXYZI>& points) {
  std::vector<Eigen::Vector2d> xy;
  xy.reserve(points.size());
  for (const roi::PointXYZI& p : points)
    xy.emplace_back(p.x, p.y);
  return xy;
}

// ---- keyframes ----------------------------------------------------------------------------

void keyframe_svg(const fs::path& dir, const eval::ScenarioRun& run, const eval::KeyframeCase& c,
                  const eval::KeyframeRow& row) {
  const auto& e = run.scenario().evaluation;
  const Window w = window_around(c.robot_pose.translation(), e.look_ahead_m + 8.0);
  char title[256];
  std::snprintf(title, sizeof title,
                "%s, %s ROI, spacing %d %% — %zu ROIs\nTP %llu  FP %llu  FN %llu  TN %llu  precision %.4f  recall %.4f "
                " accuracy %.4f",
                c.keyframe.name.c_str(), shape_name(row.shape).c_str(), row.ratio_pct, row.centres.size(),
                static_cast<unsigned long long>(row.confusion.tp), static_cast<unsigned long long>(row.confusion.fp),
                static_cast<unsigned long long>(row.confusion.fn), static_cast<unsigned long long>(row.confusion.tn),
                row.confusion.precision(), row.confusion.recall(), row.confusion.accuracy());
  eval::SvgCanvas canvas(w.x0, w.y0, w.x1, w.y1, 9.0, title);
  eval::draw_classified(canvas, xy_of(c.points), row.kept, row.truth, 1.4);
  const bool circles = row.shape == eval::RoiShape::kCircular;
  eval::draw_chain(canvas, row.centres, circles, circles ? e.circle_diameter_m : e.rect_height_m, e.rect_width_m);
  canvas.polyline(run.trajectory().waypoints(), eval::kColourTrajectory);
  char name[160];
  std::snprintf(name, sizeof name, "%s_%s_%03d.svg", c.keyframe.name.c_str(), shape_name(row.shape).c_str(),
                row.ratio_pct);
  write_file_atomically(dir / name, canvas.str());
}

void run_keyframes(const ScenarioEvalOptions& o) {
  const eval::ScenarioRun run(o.scenario);
  const eval::PoseMode mode = pose_mode(o.pose);
  const std::vector<eval::KeyframeCase> cases = eval::keyframe_cases(run, mode);
  if (!o.svg_dir.empty()) fs::create_directories(o.svg_dir);
  const bool csv = o.format == "csv", json = o.format == "json";
  if (csv) std::printf("keyframe,shape,ratio_pct,num_roi,tp,fp,fn,tn,precision,recall,accuracy,min_ms,max_ms,avg_ms\n");
  if (json)
    std::printf("{\"scenario\": \"%s\", \"pose\": \"%s\", \"reps\": %d, \"rows\": [", run.scenario().name.c_str(),
                o.pose.c_str(), o.reps);
  bool first_row = true;
  // Every row from the daemon's pipeline: one pass of the run per repetition, every shape and
  // spacing at once.
  constexpr eval::RoiShape kShapes[] = {eval::RoiShape::kCircular, eval::RoiShape::kRectangular};
  const std::vector<eval::KeyframeRow> rows =
      eval::run_keyframe_rows(run, cases, kShapes, kKeyframeRatiosPct, o.reps, mode);
  std::size_t next_row = 0;
  for (const eval::RoiShape shape : kShapes) {
    for (const eval::KeyframeCase& c : cases) {
      if (!csv && !json) {
        std::printf("\n%s, %s ROI — frame %llu, %zu points, robot at (%.2f, %.2f); times over %d passes [ms]\n",
                    c.keyframe.name.c_str(), shape_name(shape).c_str(), static_cast<unsigned long long>(c.frame_index),
                    c.points.size(), c.robot_pose.translation().x(), c.robot_pose.translation().y(), o.reps);
        std::printf("%6s %5s %7s %6s %6s %7s %9s %7s %8s %8s %8s %8s\n", "ratio", "#ROI", "TP", "FP", "FN", "TN",
                    "precision", "recall", "accuracy", "min", "max", "avg");
      }
      for (const int ratio : kKeyframeRatiosPct) {
        const eval::KeyframeRow& row = rows[next_row++];
        const roi::Confusion& k = row.confusion;
        const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
        if (csv) {
          std::printf("%s,%s,%d,%zu,%llu,%llu,%llu,%llu,%.6f,%.6f,%.6f,%.4f,%.4f,%.4f\n", row.keyframe.c_str(),
                      shape_name(shape).c_str(), ratio, row.centres.size(), u(k.tp), u(k.fp), u(k.fn), u(k.tn),
                      k.precision(), k.recall(), k.accuracy(), row.time.min_ms, row.time.max_ms, row.time.avg_ms);
        } else if (json) {
          std::printf(
              "%s\n  {\"keyframe\": \"%s\", \"shape\": \"%s\", \"ratio_pct\": %d, \"num_roi\": %zu, \"tp\": %llu, "
              "\"fp\": %llu, \"fn\": %llu, \"tn\": %llu, \"precision\": %.6f, \"recall\": %.6f, \"accuracy\": %.6f, "
              "\"min_ms\": %.4f, \"max_ms\": %.4f, \"avg_ms\": %.4f}",
              first_row ? "" : ",", row.keyframe.c_str(), shape_name(shape).c_str(), ratio, row.centres.size(), u(k.tp),
              u(k.fp), u(k.fn), u(k.tn), k.precision(), k.recall(), k.accuracy(), row.time.min_ms, row.time.max_ms,
              row.time.avg_ms);
        } else {
          std::printf("%5d%% %5zu %7llu %6llu %6llu %7llu %9.4f %7.4f %8.4f %8.3f %8.3f %8.3f\n", ratio,
                      row.centres.size(), u(k.tp), u(k.fp), u(k.fn), u(k.tn), k.precision(), k.recall(), k.accuracy(),
                      row.time.min_ms, row.time.max_ms, row.time.avg_ms);
        }
        first_row = false;
        if (!o.svg_dir.empty()) keyframe_svg(o.svg_dir, run, c, row);
        std::fflush(stdout);
      }
    }
  }
  if (json) std::printf("\n]}\n");
}

// ---- sequential ---------------------------------------------------------------------------

void run_sequential(const ScenarioEvalOptions& o) {
  const eval::ScenarioRun run(o.scenario);
  const eval::SequentialReport r = eval::run_sequential(run, pose_mode(o.pose));
  const struct {
    const char* name;
    const eval::TimingStats& t;
  } rows[] = {{"point_cloud_cycle", r.cycle}, {"circular_roi", r.circular}, {"rectangular_roi", r.rectangular}};
  if (o.format == "csv") {
    std::printf("series,frames,min_ms,max_ms,avg_ms\n");
    for (const auto& row : rows)
      std::printf("%s,%zu,%.4f,%.4f,%.4f\n", row.name, r.frames, row.t.min_ms, row.t.max_ms, row.t.avg_ms);
  } else if (o.format == "json") {
    std::printf(
        "{\"scenario\": \"%s\", \"frames\": %zu, \"skipped_no_pose\": %zu, \"skipped_partial\": %zu, \"avg_points\": "
        "%.2f",
        run.scenario().name.c_str(), r.frames, r.skipped_no_pose, r.skipped_partial, r.avg_points);
    for (const auto& row : rows) {
      std::printf(", \"%s\": {\"min_ms\": %.4f, \"max_ms\": %.4f, \"avg_ms\": %.4f}", row.name, row.t.min_ms,
                  row.t.max_ms, row.t.avg_ms);
    }
    std::printf("}\n");
  } else {
    std::printf(
        "%s: %zu sequential frames (%.0f points on average; %zu without a valid pose, %zu partial skipped), spacing 25 "
        "%%\n",
        run.scenario().name.c_str(), r.frames, r.avg_points, r.skipped_no_pose, r.skipped_partial);
    std::printf("%-34s %9s %9s %9s\n", "[ms]", "min", "max", "avg");
    std::printf("%-34s %9.3f %9.3f %9.3f\n", "point cloud cycle", r.cycle.min_ms, r.cycle.max_ms, r.cycle.avg_ms);
    std::printf("%-34s %9.3f %9.3f %9.3f\n", "circular ROI processing time", r.circular.min_ms, r.circular.max_ms,
                r.circular.avg_ms);
    std::printf("%-34s %9.3f %9.3f %9.3f\n", "rectangular ROI processing time", r.rectangular.min_ms,
                r.rectangular.max_ms, r.rectangular.avg_ms);
    if (r.circular.avg_ms > 0.0 && r.rectangular.avg_ms > 0.0) {
      std::printf("faster than the data: %.0fx (circular), %.0fx (rectangular) on average\n",
                  r.cycle.avg_ms / r.circular.avg_ms, r.cycle.avg_ms / r.rectangular.avg_ms);
    }
    std::printf(
        "(time per frame: decoding its packets, placing it with the pose, centres, ROI set, grid and filter)\n");
  }
  if (!o.svg_dir.empty()) {
    fs::create_directories(o.svg_dir);
    eval::SvgChart chart("Sequential frames: processing time and point cloud cycle (cf. the paper's Fig. 22)", "frame",
                         "time [ms]");
    std::vector<std::pair<double, double>> cycle, circ, rect;
    for (const eval::FrameTiming& f : r.per_frame) {
      if (f.cycle_ms > 0.0) cycle.emplace_back(static_cast<double>(f.frame_index), f.cycle_ms);
      circ.emplace_back(static_cast<double>(f.frame_index), f.circular_ms);
      rect.emplace_back(static_cast<double>(f.frame_index), f.rectangular_ms);
    }
    chart.line("point cloud cycle", "#7f7f7f", cycle);
    chart.line("circular ROI", eval::kColourRoi, circ);
    chart.line("rectangular ROI", "#d62728", rect);
    write_file_atomically(fs::path(o.svg_dir) / "sequential.svg", chart.str());
  }
}

// ---- accumulated --------------------------------------------------------------------------

void run_accumulated(const ScenarioEvalOptions& o) {
  const eval::ScenarioRun run(o.scenario);
  const eval::AccumulatedReport r = eval::run_accumulated(run, pose_mode(o.pose));
  const auto fit_of = [&](eval::RoiShape s) -> const eval::LinearFit& {
    return s == eval::RoiShape::kCircular ? r.circular_fit : r.rectangular_fit;
  };
  if (o.format == "csv") {
    std::printf("shape,frames_per_cloud,clouds,avg_points,min_ms,max_ms,avg_ms\n");
    for (const auto& row : r.rows) {
      std::printf("%s,%d,%zu,%.2f,%.4f,%.4f,%.4f\n", shape_name(row.shape).c_str(), row.frames_per_cloud, row.clouds,
                  row.avg_points, row.time.min_ms, row.time.max_ms, row.time.avg_ms);
    }
  } else if (o.format == "json") {
    std::printf("{\"scenario\": \"%s\", \"rows\": [", run.scenario().name.c_str());
    for (std::size_t i = 0; i < r.rows.size(); ++i) {
      const auto& row = r.rows[i];
      std::printf(
          "%s\n  {\"shape\": \"%s\", \"frames_per_cloud\": %d, \"clouds\": %zu, \"avg_points\": %.2f, \"min_ms\": "
          "%.4f, "
          "\"max_ms\": %.4f, \"avg_ms\": %.4f}",
          i == 0 ? "" : ",", shape_name(row.shape).c_str(), row.frames_per_cloud, row.clouds, row.avg_points,
          row.time.min_ms, row.time.max_ms, row.time.avg_ms);
    }
    std::printf("\n], \"fits\": {");
    for (const eval::RoiShape s : {eval::RoiShape::kCircular, eval::RoiShape::kRectangular}) {
      const eval::LinearFit& f = fit_of(s);
      std::printf("%s\"%s\": {\"ms_per_million_points\": %.4f, \"intercept_ms\": %.4f, \"r2\": %.6f}",
                  s == eval::RoiShape::kCircular ? "" : ", ", shape_name(s).c_str(), f.slope_ms_per_mpoint,
                  f.intercept_ms, f.r2);
    }
    std::printf("}}\n");
  } else {
    std::printf("%s: frames accumulated in the global frame, spacing 25 %% (time: centres, ROI set, grid, filter)\n",
                run.scenario().name.c_str());
    std::printf("%-12s %6s %7s %12s %9s %9s %9s\n", "shape", "frames", "clouds", "avg points", "min ms", "max ms",
                "avg ms");
    for (const auto& row : r.rows) {
      std::printf("%-12s %6d %7zu %12.2f %9.3f %9.3f %9.3f\n", shape_name(row.shape).c_str(), row.frames_per_cloud,
                  row.clouds, row.avg_points, row.time.min_ms, row.time.max_ms, row.time.avg_ms);
    }
    for (const eval::RoiShape s : {eval::RoiShape::kCircular, eval::RoiShape::kRectangular}) {
      const eval::LinearFit& f = fit_of(s);
      std::printf("%s: time = %.3f ms + %.3f ms per million points, R² = %.4f\n", shape_name(s).c_str(), f.intercept_ms,
                  f.slope_ms_per_mpoint, f.r2);
    }
  }
  if (!o.svg_dir.empty()) {
    fs::create_directories(o.svg_dir);
    eval::SvgChart chart("Accumulated frames: processing time against points (cf. the paper's Fig. 23)",
                         "points per cloud", "time [ms]");
    chart.dots("circular ROI", eval::kColourRoi, r.circular_samples);
    chart.dots("rectangular ROI", "#d62728", r.rectangular_samples);
    for (const eval::RoiShape s : {eval::RoiShape::kCircular, eval::RoiShape::kRectangular}) {
      const auto& samples = s == eval::RoiShape::kCircular ? r.circular_samples : r.rectangular_samples;
      double max_points = 0.0;
      for (const auto& p : samples)
        max_points = std::max(max_points, p.first);
      const eval::LinearFit& f = fit_of(s);
      chart.line(shape_name(s) + " fit", s == eval::RoiShape::kCircular ? "#17becf" : "#ff9896",
                 {{0.0, f.intercept_ms}, {max_points, f.intercept_ms + f.slope_ms_per_mpoint * max_points * 1e-6}});
    }
    write_file_atomically(fs::path(o.svg_dir) / "accumulated.svg", chart.str());
  }
}

// ---- render (Table 20) --------------------------------------------------------------------

struct RenderOptions {
  std::string scenario;
  std::string keyframe;
  std::string out;
  double range_m = 60.0;
};

void run_render(const RenderOptions& o) {
  const eval::ScenarioRun run(o.scenario);
  const std::vector<eval::KeyframeCase> cases = eval::keyframe_cases(run, eval::PoseMode::kPerFiring);
  const eval::KeyframeCase* c = nullptr;
  for (const auto& candidate : cases) {
    if (o.keyframe.empty() || candidate.keyframe.name == o.keyframe) {
      c = &candidate;
      break;
    }
  }
  if (c == nullptr) throw std::runtime_error(o.scenario + ": no keyframe named '" + o.keyframe + "'");
  const auto& e = run.scenario().evaluation;
  const Window w = window_around(c->robot_pose.translation(), o.range_m);
  const std::vector<Eigen::Vector2d> xy = xy_of(c->points);
  const std::span<const roi::PointXYZI> points(c->points);
  std::vector<eval::SvgCanvas> panels;
  const auto panel = [&](const char* title, const roi::IndexVector* kept) -> eval::SvgCanvas& {
    char text[200];
    std::snprintf(text, sizeof text, "%s\n%zu of %zu points", title, kept != nullptr ? kept->size() : xy.size(),
                  xy.size());
    eval::SvgCanvas& canvas = panels.emplace_back(w.x0, w.y0, w.x1, w.y1, 5.0, text);
    std::vector<std::uint8_t> mask(xy.size(), kept == nullptr ? 1 : 0);
    if (kept != nullptr) {
      for (const std::uint32_t i : *kept)
        mask[i] = 1;
    }
    for (std::size_t i = 0; i < xy.size(); ++i) {
      canvas.dot(xy[i].x(), xy[i].y(),
                 mask[i] != 0 ? (kept == nullptr ? eval::kColourRaw : eval::kColourTp) : eval::kColourTn, 1.2);
    }
    canvas.polyline(run.trajectory().waypoints(), eval::kColourTrajectory);
    return canvas;
  };
  panel("Raw point cloud", nullptr);

  // The long cuboid around the robot (the paper's [20]): length × width, z from the ground up.
  const roi::CuboidRoi cuboid(c->robot_pose,
                              roi::centred_cuboid(e.cuboid_length_m, e.cuboid_width_m, -1.0, e.cuboid_height_m - 1.0));
  roi::IndexVector cuboid_kept;
  (void)roi::cuboid_filter(cuboid, points, cuboid_kept);
  eval::SvgCanvas& cuboid_panel = panel("Long cuboid ROI", &cuboid_kept);
  {
    const Eigen::Vector3d t = c->robot_pose.translation();
    const Eigen::Matrix3d r = c->robot_pose.linear();
    const double hl = e.cuboid_length_m / 2.0, hw = e.cuboid_width_m / 2.0;
    Eigen::Vector2d corners[4];
    const double sx[4] = {-hl, -hl, hl, hl}, sy[4] = {-hw, hw, hw, -hw};
    for (int k = 0; k < 4; ++k)
      corners[k] = (t + r * Eigen::Vector3d(sx[k], sy[k], 0.0)).head<2>();
    cuboid_panel.polygon(corners, eval::kColourRoi, 1.5);
  }
  // The trajectory ROIs, from the robot to the end of the trajectory at 25 % (the paper's
  // Table 20 set-up).
  eval::RoiChain chain(e);
  for (const eval::RoiShape shape : {eval::RoiShape::kCircular, eval::RoiShape::kRectangular}) {
    const bool circles = shape == eval::RoiShape::kCircular;
    chain.run(run.trajectory(), c->s0_m, std::numeric_limits<double>::infinity(), shape, 25, points);
    eval::SvgCanvas& canvas = panel(circles ? "Circular ROI (25 %)" : "Rectangular ROI (25 %)", &chain.kept());
    eval::draw_chain(canvas, chain.centres(), circles, circles ? e.circle_diameter_m : e.rect_height_m, e.rect_width_m);
  }
  write_file_atomically(o.out, eval::side_by_side(panels));
  std::printf("%s: %s, frame %llu, %zu points → %s\n", run.scenario().name.c_str(), c->keyframe.name.c_str(),
              static_cast<unsigned long long>(c->frame_index), c->points.size(), o.out.c_str());
}

}  // namespace

void add_scenario_eval_commands(CLI::App& eval_cmd) {
  struct Entry {
    const char* name;
    const char* help;
    void (*run)(const ScenarioEvalOptions&);
  };
  const Entry entries[] = {
      {"keyframes", "Tables 9 and 11: both ROIs on the scenario's keyframes at spacings 100/75/50/25 %", run_keyframes},
      {"sequential", "Table 18: every frame through decode, pose, ROI; processing time against the data cycle",
       run_sequential},
      {"accumulated", "Table 19: 1 … 100 frames accumulated; time against points with a linear fit", run_accumulated},
  };
  for (const Entry& entry : entries) {
    auto options = std::make_shared<ScenarioEvalOptions>();
    CLI::App* cmd = eval_cmd.add_subcommand(entry.name, entry.help);
    add_common_options(cmd, *options);
    if (entry.run == run_keyframes) {
      cmd->add_option("--reps", options->reps, "Timed passes of the run (keyframes: every row in each pass)")
          ->check(CLI::Range(1, 100000))
          ->capture_default_str();
    }
    const auto run = entry.run;
    cmd->callback([options, run] { run(*options); });
  }
}

void add_render_command(CLI::App& app) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Table 20: one keyframe top-down — raw cloud, long cuboid, circular and rectangular ROIs side by side (SVG)");
  cmd->add_option("--scenario", options->scenario, "Run folder written by `trajroi sim`")->required();
  cmd->add_option("--keyframe", options->keyframe, "Keyframe name (default: the first)");
  cmd->add_option("--out", options->out, "SVG file to write")->required();
  cmd->add_option("--range", options->range_m, "Half-width of the picture around the robot, m")
      ->check(CLI::Range(5.0, 500.0))
      ->capture_default_str();
  cmd->callback([options] { run_render(*options); });
}

}  // namespace trajroi::cli
