#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.hpp"
#include "file_io.hpp"
#include "trajroi/eval/points_csv.hpp"
#include "trajroi/roi/cuboid.hpp"
#include "trajroi/roi/grid_filter.hpp"
#include "trajroi/roi/reference_filter.hpp"
#include "trajroi/roi/roi_chain.hpp"
#include "trajroi/roi/shapes.hpp"
#include "trajroi/roi/text.hpp"
#include "trajroi/roi/transform.hpp"

namespace trajroi::cli {
namespace {

struct FilterOptions {
  std::string trajectory_path;
  std::string points_path;
  std::string shape;
  std::optional<double> diameter_m;
  std::optional<double> height_m;
  std::optional<double> width_m;
  std::optional<double> length_m;
  std::optional<double> spacing_m;
  std::optional<double> spacing_ratio;
  double z_min_m = -std::numeric_limits<double>::infinity();
  double z_max_m = std::numeric_limits<double>::infinity();
  std::string pose = "0,0,0";
  double start_s_m = 0.0;
  double look_ahead_m = std::numeric_limits<double>::infinity();
  std::string cloud_precision = "double";
  std::string algorithm = "fast";
  std::string output_path;
};

double require(const std::optional<double>& value, const char* option, const std::string& shape) {
  if (!value) throw std::invalid_argument(std::string(option) + " is required for --shape " + shape);
  return *value;
}

// 'x_m,y_m,yaw_deg' (planar), or 'x,y,z,qw,qx,qy,qz' (a full pose as trajroid publishes it,
// rebuilt exactly as trajroid rebuilds it).
Eigen::Isometry3d parse_pose(const std::string& text) {
  double v[7];
  const std::size_t n = roi::parse_csv_doubles(text, v);
  const bool finite = std::all_of(v, v + std::min<std::size_t>(n, 7), [](double x) { return std::isfinite(x); });
  if (n == 3 && finite) return roi::pose_from_xy_yaw(v[0], v[1], v[2] * std::numbers::pi / 180.0);
  if (n == 7 && finite) {
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-9) {
      throw std::invalid_argument("--pose: the quaternion (qw,qx,qy,qz) must have unit norm, got '" + text + "'");
    }
    return roi::pose_from_position_quaternion(Eigen::Vector3d(v[0], v[1], v[2]), q);
  }
  throw std::invalid_argument("--pose expects 'x_m,y_m,yaw_deg' or 'x,y,z,qw,qx,qy,qz' with finite numbers, got '" +
                              text + "'");
}

double spacing(const FilterOptions& o, double size_along_m) {
  if (o.spacing_m.has_value() == o.spacing_ratio.has_value()) {
    throw std::invalid_argument("give exactly one of --spacing and --spacing-ratio for --shape " + o.shape);
  }
  if (o.spacing_m) return *o.spacing_m;
  if (!std::isfinite(*o.spacing_ratio) || *o.spacing_ratio <= 0.0) {
    throw std::invalid_argument("--spacing-ratio must be finite and positive, got " + std::to_string(*o.spacing_ratio));
  }
  return roi::spacing_from_ratio(*o.spacing_ratio, size_along_m);
}

template <typename RoiSet>
roi::FilterStats run_chain(const RoiSet& set, const std::string& algorithm, std::span<const roi::PointXYZd> points,
                           roi::IndexVector& kept) {
  if (algorithm == "reference") return roi::reference_filter(set, points, kept);
  roi::GridFilter<RoiSet> grid;
  grid.build(set);
  return grid.filter(points, kept);
}

void run_filter(const FilterOptions& o) {
  // Read and validate everything first: on any error nothing is written.
  const roi::Trajectory trajectory = roi::parse_trajectory_csv(read_text_file(o.trajectory_path), o.trajectory_path);
  std::vector<roi::PointXYZd> points = eval::parse_points_csv(read_text_file(o.points_path), o.points_path);
  const Eigen::Isometry3d global_from_sensor = parse_pose(o.pose);
  roi::transform_points(global_from_sensor, points, points);
  if (o.cloud_precision == "float") {
    // As trajroid stores placed points (and LCM carries them): float32.
    for (roi::PointXYZd& p : points) {
      p = {static_cast<double>(static_cast<float>(p.x)), static_cast<double>(static_cast<float>(p.y)),
           static_cast<double>(static_cast<float>(p.z))};
    }
  }
  const roi::ZLimits z{o.z_min_m, o.z_max_m};
  const double inf = std::numeric_limits<double>::infinity();

  roi::IndexVector kept;
  roi::FilterStats stats;
  std::vector<roi::Centre> centres;
  if (o.shape == "circular" || o.shape == "rectangular") {
    // The chain the daemon places each sweep (roi::RoiChain), or the paper's double loop over
    // the same shapes.
    const bool circular = o.shape == "circular";
    roi::ChainSize size;
    if (circular) {
      size.radius_m = require(o.diameter_m, "--diameter", o.shape) / 2.0;
    } else {
      size.height_m = require(o.height_m, "--height", o.shape);
      size.width_m = require(o.width_m, "--width", o.shape);
    }
    const double spacing_m = spacing(o, circular ? 2.0 * size.radius_m : size.height_m);
    roi::place_centres(trajectory, o.start_s_m, o.look_ahead_m, spacing_m, centres);  // checks the spacing first
    const std::span<const roi::PointXYZd> cloud(points);
    if (o.algorithm == "reference") {
      stats = circular
                  ? roi::reference_filter(roi::CircularRoiSet(size.radius_m, centres, z), cloud, kept)
                  : roi::reference_filter(roi::RectangularRoiSet(size.height_m, size.width_m, centres, z), cloud, kept);
    } else {
      roi::RoiChain chain(circular ? roi::RoiShape::kCircular : roi::RoiShape::kRectangular, size, z);
      chain.place(trajectory, o.start_s_m, o.look_ahead_m, spacing_m, size);
      stats = chain.filter(cloud, kept);
    }
  } else if (o.shape == "corridor") {
    const double width = require(o.width_m, "--width", o.shape);
    stats = run_chain(roi::CorridorRoiSet(trajectory, 0.0, inf, width, z), o.algorithm, points, kept);
  } else {  // cuboid: one box around the robot, in the robot (= sensor) frame
    const double length = require(o.length_m, "--length", o.shape);
    const double width = require(o.width_m, "--width", o.shape);
    if (!(length > 0.0) || !(width > 0.0)) {
      throw std::invalid_argument("cuboid --length and --width must be positive");
    }
    const roi::CuboidRoi cuboid(global_from_sensor, roi::centred_cuboid(length, width, o.z_min_m, o.z_max_m));
    stats = roi::cuboid_filter(cuboid, std::span<const roi::PointXYZd>(points), kept);
  }

  std::string out;
  out.reserve(kept.size() * 8);
  for (const std::uint32_t i : kept) {
    out += std::to_string(i);
    out += '\n';
  }
  write_file_atomically(o.output_path, out);
  std::fprintf(stderr, "trajroi filter: %zu points in, %zu kept, %zu non-finite dropped, %zu outside z limits\n",
               stats.input, stats.kept, stats.non_finite, stats.outside_z);
}

}  // namespace

void add_filter_command(CLI::App& app) {
  auto o = std::make_shared<FilterOptions>();
  CLI::App* cmd =
      app.add_subcommand("filter", "Keep the points of a CSV cloud inside a trajectory ROI; write their indices");
  cmd->add_option("--trajectory", o->trajectory_path, "Trajectory CSV: 'x,y' per line (global frame, m)")->required();
  cmd->add_option("--points", o->points_path, "Points CSV: 'x,y,z[,intensity]' per line (sensor frame, m)")->required();
  cmd->add_option("--shape", o->shape, "ROI method")
      ->required()
      ->check(CLI::IsMember({"circular", "rectangular", "corridor", "cuboid"}));
  cmd->add_option("--diameter", o->diameter_m, "Circle diameter 2r [m] (circular)");
  cmd->add_option("--height", o->height_m, "Rectangle height a along the tangent [m] (rectangular)");
  cmd->add_option("--width", o->width_m, "Rectangle width b / corridor width / cuboid width [m]");
  cmd->add_option("--length", o->length_m, "Cuboid length along the robot's x axis [m] (cuboid)");
  auto* spacing_opt = cmd->add_option("--spacing", o->spacing_m, "Distance d between centres [m]");
  auto* ratio_opt = cmd->add_option("--spacing-ratio", o->spacing_ratio,
                                    "d as a fraction of the diameter (circular) or height (rectangular): 0.25 = 25 %");
  spacing_opt->excludes(ratio_opt);
  cmd->add_option("--z-min", o->z_min_m, "Lowest z kept [m] (global frame; robot frame for cuboid)");
  cmd->add_option("--z-max", o->z_max_m, "Highest z kept [m]");
  cmd->add_option("--pose", o->pose, "Sensor pose: 'x_m,y_m,yaw_deg', or 'x,y,z,qw,qx,qy,qz' as in trajroid's points_t")
      ->capture_default_str();
  cmd->add_option("--start-s", o->start_s_m, "Arc length of the first centre [m] (circular, rectangular)")
      ->capture_default_str();
  cmd->add_option("--look-ahead", o->look_ahead_m, "Chain length from --start-s [m] (default: to the end)");
  cmd->add_option("--cloud-precision", o->cloud_precision,
                  "Precision of the placed points: double, or float as trajroid stores them")
      ->check(CLI::IsMember({"double", "float"}))
      ->capture_default_str();
  cmd->add_option("--algorithm", o->algorithm, "Membership implementation")
      ->check(CLI::IsMember({"reference", "fast"}))
      ->capture_default_str();
  cmd->add_option("--output-indices", o->output_path, "Write 0-based kept indices here, ascending")->required();
  cmd->callback([o] { run_filter(*o); });
}

}  // namespace trajroi::cli
