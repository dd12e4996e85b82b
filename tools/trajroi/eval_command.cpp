#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.hpp"
#include "file_io.hpp"
#include "trajroi/eval/artificial.hpp"
#include "trajroi/eval/svg.hpp"

namespace trajroi::cli {
namespace {

struct ArtificialOptions {
  std::string data = "both";
  std::string shape = "both";
  int reps = 100;
  std::string format = "table";
  std::string svg_dir;
};

std::vector<eval::ArtificialData> selected_data(const std::string& name) {
  if (name == "straight") return {eval::ArtificialData::kStraight};
  if (name == "curved") return {eval::ArtificialData::kCurved};
  return {eval::ArtificialData::kStraight, eval::ArtificialData::kCurved};
}

std::vector<eval::RoiShape> selected_shapes(const std::string& name) {
  if (name == "circular") return {eval::RoiShape::kCircular};
  if (name == "rectangular") return {eval::RoiShape::kRectangular};
  return {eval::RoiShape::kCircular, eval::RoiShape::kRectangular};
}

void write_row_svg(const std::filesystem::path& dir, const eval::ArtificialScene& scene,
                   const eval::ArtificialRow& row) {
  const bool straight = scene.data == eval::ArtificialData::kStraight;
  char title[200];
  std::snprintf(title, sizeof title,
                "%s data, %s ROI, spacing %d %% (%.2f m)\n%zu ROIs — TP %llu, FP %llu, FN %llu, TN %llu",
                std::string(to_string(row.data)).c_str(), std::string(to_string(row.shape)).c_str(), row.ratio_pct,
                row.spacing_m, row.centres.size(), static_cast<unsigned long long>(row.confusion.tp),
                static_cast<unsigned long long>(row.confusion.fp), static_cast<unsigned long long>(row.confusion.fn),
                static_cast<unsigned long long>(row.confusion.tn));
  eval::SvgCanvas canvas = straight ? eval::SvgCanvas(-4.0, -8.0, 87.0, 8.0, 12.0, title)
                                    : eval::SvgCanvas(-4.0, -8.0, 58.0, 57.0, 12.0, title);
  std::vector<Eigen::Vector2d> xy;
  xy.reserve(scene.points.size());
  for (const roi::PointXYZd& p : scene.points)
    xy.emplace_back(p.x, p.y);
  draw_classified(canvas, xy, row.kept, scene.truth, 1.6);
  const bool circles = row.shape == eval::RoiShape::kCircular;
  draw_chain(canvas, row.centres, circles, circles ? eval::kCircleDiameter_m : eval::kRectHeight_m, eval::kRectWidth_m);
  canvas.polyline(scene.trajectory.waypoints(), eval::kColourTrajectory);
  char name[96];
  std::snprintf(name, sizeof name, "%s_%s_%03d.svg", std::string(to_string(row.data)).c_str(),
                std::string(to_string(row.shape)).c_str(), row.ratio_pct);
  write_file_atomically(dir / name, canvas.str());
}

void print_csv_header() {
  std::printf(
      "data,shape,ratio_pct,num_roi,tp,fp,fn,tn,precision,recall,accuracy,ref_min_ms,ref_max_ms,"
      "ref_avg_ms,fast_min_ms,fast_max_ms,fast_avg_ms\n");
}

void print_csv_row(const eval::ArtificialRow& r) {
  const roi::Confusion& c = r.confusion;
  std::printf("%s,%s,%d,%zu,%llu,%llu,%llu,%llu,%.6f,%.6f,%.6f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n",
              std::string(to_string(r.data)).c_str(), std::string(to_string(r.shape)).c_str(), r.ratio_pct,
              r.centres.size(), static_cast<unsigned long long>(c.tp), static_cast<unsigned long long>(c.fp),
              static_cast<unsigned long long>(c.fn), static_cast<unsigned long long>(c.tn), c.precision(), c.recall(),
              c.accuracy(), r.reference.min_ms, r.reference.max_ms, r.reference.avg_ms, r.fast.min_ms, r.fast.max_ms,
              r.fast.avg_ms);
}

void print_table_header(eval::ArtificialData data, eval::RoiShape shape, std::size_t points, int reps) {
  std::printf("\n%s data (%zu points), %s ROI — times over %d repetitions [ms]\n", std::string(to_string(data)).c_str(),
              points, std::string(to_string(shape)).c_str(), reps);
  std::printf("%6s %5s %7s %6s %7s %7s %9s %7s %8s  %-23s %-23s %7s\n", "ratio", "#ROI", "TP", "FP", "FN", "TN",
              "precision", "recall", "accuracy", "reference min/max/avg", "fast min/max/avg", "speedup");
}

void print_table_row(const eval::ArtificialRow& r) {
  const roi::Confusion& c = r.confusion;
  char reference[40];
  char fast[40];
  std::snprintf(reference, sizeof reference, "%.3f/%.3f/%.3f", r.reference.min_ms, r.reference.max_ms,
                r.reference.avg_ms);
  std::snprintf(fast, sizeof fast, "%.3f/%.3f/%.3f", r.fast.min_ms, r.fast.max_ms, r.fast.avg_ms);
  std::printf("%5d%% %5zu %7llu %6llu %7llu %7llu %9.4f %7.4f %8.4f  %-23s %-23s %6.1fx\n", r.ratio_pct,
              r.centres.size(), static_cast<unsigned long long>(c.tp), static_cast<unsigned long long>(c.fp),
              static_cast<unsigned long long>(c.fn), static_cast<unsigned long long>(c.tn), c.precision(), c.recall(),
              c.accuracy(), reference, fast, r.reference.avg_ms / r.fast.avg_ms);
}

void print_json_row(const eval::ArtificialRow& r, bool first) {
  const roi::Confusion& c = r.confusion;
  std::printf(
      "%s\n  {\"data\": \"%s\", \"shape\": \"%s\", \"ratio_pct\": %d, \"num_roi\": %zu, \"tp\": %llu, \"fp\": %llu, "
      "\"fn\": %llu, \"tn\": %llu, \"precision\": %.6f, \"recall\": %.6f, \"accuracy\": %.6f, "
      "\"fast_equals_reference\": %s, \"reference\": {\"min_ms\": %.4f, \"max_ms\": %.4f, \"avg_ms\": %.4f}, "
      "\"fast\": {\"min_ms\": %.4f, \"max_ms\": %.4f, \"avg_ms\": %.4f}}",
      first ? "" : ",", std::string(to_string(r.data)).c_str(), std::string(to_string(r.shape)).c_str(), r.ratio_pct,
      r.centres.size(), static_cast<unsigned long long>(c.tp), static_cast<unsigned long long>(c.fp),
      static_cast<unsigned long long>(c.fn), static_cast<unsigned long long>(c.tn), c.precision(), c.recall(),
      c.accuracy(), r.fast_equals_reference ? "true" : "false", r.reference.min_ms, r.reference.max_ms,
      r.reference.avg_ms, r.fast.min_ms, r.fast.max_ms, r.fast.avg_ms);
}

void run_artificial(const ArtificialOptions& options) {
  const bool csv = options.format == "csv";
  const bool json = options.format == "json";
  if (!options.svg_dir.empty()) std::filesystem::create_directories(options.svg_dir);
  if (csv) print_csv_header();
  if (json) std::printf("{\"reps\": %d, \"rows\": [", options.reps);
  bool first = true;
  bool all_equal = true;
  for (const eval::ArtificialData data : selected_data(options.data)) {
    const eval::ArtificialScene scene = eval::make_artificial_scene(data);
    for (const eval::RoiShape shape : selected_shapes(options.shape)) {
      if (!csv && !json) print_table_header(data, shape, scene.points.size(), options.reps);
      for (const int ratio : eval::kPaperRatiosPct) {
        const eval::ArtificialRow row = eval::run_artificial_row(scene, shape, ratio, options.reps);
        all_equal = all_equal && row.fast_equals_reference;
        if (csv) {
          print_csv_row(row);
        } else if (json) {
          print_json_row(row, first);
        } else {
          print_table_row(row);
        }
        first = false;
        if (!options.svg_dir.empty()) write_row_svg(options.svg_dir, scene, row);
        std::fflush(stdout);
      }
    }
  }
  if (json) std::printf("\n]}\n");
  if (!all_equal) {
    throw std::runtime_error("the fast filter kept a different set of points than the reference");
  }
  if (!csv && !json) std::printf("\nfast filter == reference double loop on every point of every row\n");
}

}  // namespace

void add_eval_commands(CLI::App& app) {
  CLI::App* eval_cmd = app.add_subcommand("eval", "Reproduce the paper's evaluations");
  eval_cmd->require_subcommand(1);

  auto options = std::make_shared<ArtificialOptions>();
  CLI::App* artificial =
      eval_cmd->add_subcommand("artificial", "Tables 3 and 5: circular and rectangular ROIs on the artificial frames");
  artificial->add_option("--data", options->data, "Point set")
      ->check(CLI::IsMember({"straight", "curved", "both"}))
      ->capture_default_str();
  artificial->add_option("--shape", options->shape, "ROI shape")
      ->check(CLI::IsMember({"circular", "rectangular", "both"}))
      ->capture_default_str();
  artificial->add_option("--reps", options->reps, "Timed repetitions per row")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  artificial->add_option("--format", options->format, "Output format")
      ->check(CLI::IsMember({"table", "csv", "json"}))
      ->capture_default_str();
  artificial->add_option("--svg", options->svg_dir,
                         "Write one top-down SVG per row (TP/FP/FN/TN, ROIs, trajectory) here");
  artificial->callback([options] { run_artificial(*options); });
  add_scenario_eval_commands(*eval_cmd);
}

}  // namespace trajroi::cli
