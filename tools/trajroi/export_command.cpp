// trajroi export: trajroid's kept points into files other tools open — PCD v0.7, PLY, and LAS
// 1.4 georeferenced in UTM — one per sweep or one accumulated map. The sweeps come from an LCM
// log (lcm-logger's, or trajroid's file:// LCM URL) or from a run folder replayed through the
// per-sweep pipeline (export_sources.hpp). A log cut short is exported up to the cut, which is
// named, and the command then fails; every file is written whole or not at all.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "commands.hpp"
#include "export_sources.hpp"
#include "file_io.hpp"
#include "trajroi/cloud_io/cloud.hpp"
#include "trajroi/cloud_io/las.hpp"
#include "trajroi/cloud_io/pcd.hpp"
#include "trajroi/cloud_io/ply.hpp"
#include "trajroi/daemon/config.hpp"

namespace trajroi::cli {

namespace {

namespace fs = std::filesystem;

struct ExportOptions {
  std::string source;
  std::string format = "pcd";
  std::string pcd_data = "binary";
  std::string out;
  std::string channel = "TRAJROI_POINTS";
  std::string config;          // a trajroid.yaml: the origin (LAS), a run folder's pipeline
  std::vector<double> origin;  // lat, lon, height: the global frame's origin (LAS)
  bool accumulate = false;
  double voxel_m = 0.0;
  bool quiet = false;
};

// The global frame's origin for LAS: --origin, else --config's, else the run folder's.
cloud_io::UtmProjection projection(const ExportOptions& o) {
  if (o.origin.size() == 3) return {o.origin[0], o.origin[1], o.origin[2]};
  fs::path config = o.config;
  if (config.empty() && fs::is_directory(o.source)) config = fs::path(o.source) / "trajroid.yaml";
  if (config.empty()) {
    throw std::runtime_error(
        "--format las places the points on the map: give the global frame's origin with --config "
        "trajroid.yaml (global_frame.origin) or --origin LAT,LON,HEIGHT");
  }
  const daemon::DaemonConfig c = daemon::load_daemon_config(config);
  return {c.origin.lat_deg, c.origin.lon_deg, c.origin.height_m};
}

class Encoder {
 public:
  explicit Encoder(const ExportOptions& o) : o_(o) {
    if (o.format != "pcd" && o.format != "ply" && o.format != "las")
      throw std::runtime_error("--format " + o.format + ": pcd, ply or las");
    (void)cloud_io::pcd_data_from(o.pcd_data);  // checked before anything is written
    if (o.format == "las") {
      utm_.emplace(projection(o));
      const std::time_t now = std::time(nullptr);
      std::tm t{};
      gmtime_r(&now, &t);
      text_.creation_day_of_year = t.tm_yday + 1;
      text_.creation_year = t.tm_year + 1900;
      text_.generating_software = "trajroi " TRAJROI_VERSION;
    }
  }
  [[nodiscard]] std::vector<std::uint8_t> encode(const cloud_io::Cloud& cloud) const {
    if (o_.format == "ply") return cloud_io::encode_ply(cloud);
    if (o_.format == "las") return cloud_io::encode_las(cloud, *utm_, text_);
    return cloud_io::encode_pcd(cloud, cloud_io::pcd_data_from(o_.pcd_data));
  }
  [[nodiscard]] std::string crs() const {
    return utm_ ? ", UTM zone " + std::to_string(utm_->zone()) + (utm_->northern() ? "N" : "S") +
                      " (EPSG:" + std::to_string(utm_->epsg()) + ")"
                : std::string();
  }

 private:
  const ExportOptions& o_;
  std::optional<cloud_io::UtmProjection> utm_;
  cloud_io::LasHeaderText text_;
};

void write(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  write_file_atomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

void run_export(const ExportOptions& o) {
  const Encoder encoder(o);
  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) throw std::runtime_error(o.out + ": cannot create the output folder: " + ec.message());

  cloud_io::Accumulator map(o.voxel_m);
  std::uint64_t points = 0;
  const SweepHandler on_sweep = [&](const ExportSweep& s) {
    if (o.accumulate) {
      map.add(s.cloud, s.start_ns);
    } else {
      char name[48];
      std::snprintf(name, sizeof name, "sweep_%06lld.%s", static_cast<long long>(s.index), o.format.c_str());
      write(fs::path(o.out) / name, encoder.encode(s.cloud));
    }
    points += s.cloud.size();
  };
  auto last_progress = std::chrono::steady_clock::now();
  const Progress progress = [&](double done, std::uint64_t sweeps) {
    const auto now = std::chrono::steady_clock::now();
    if (o.quiet || now - last_progress < std::chrono::seconds(1)) return;
    std::fprintf(stderr, "trajroi export: %.0f %% of %s, %llu sweeps\n", 100.0 * done, o.source.c_str(),
                 static_cast<unsigned long long>(sweeps));
    last_progress = now;
  };
  const bool run_folder = fs::is_directory(o.source);
  const SourceSummary summary = run_folder ? replay_run_folder(o.source, o.config, on_sweep, progress)
                                           : read_lcm_log(o.source, o.channel, on_sweep, progress);
  std::uint64_t written = points;
  if (o.accumulate && summary.sweeps > 0) {
    written = map.cloud().size();
    write(fs::path(o.out) / ("map." + o.format), encoder.encode(map.cloud()));
  }
  std::printf("trajroi export: %llu sweeps, %llu points %s%s in %s%s (from %s); skipped %s\n",
              static_cast<unsigned long long>(summary.sweeps), static_cast<unsigned long long>(written),
              o.accumulate ? "(the map) " : "", o.format.c_str(), o.out.c_str(), encoder.crs().c_str(),
              run_folder ? "the run folder replayed through the pipeline" : "the LCM log", summary.skipped.c_str());
  if (!summary.cut.empty()) {
    throw std::runtime_error(summary.cut + "; the " + std::to_string(summary.sweeps) +
                             " sweeps before it are exported");
  }
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write trajroid's kept points as PCD, PLY or LAS (georeferenced) files, from an LCM log (lcm-logger, or a "
      "file:// LCM URL) or a run folder replayed through the pipeline");
  cmd->add_option("source", o->source, "LCM log, or run folder (lidar.pcap, gnss.trjb, imu.trjb, trajroid.yaml)")
      ->required()
      ->check(CLI::ExistingPath);
  cmd->add_option("--format", o->format, "pcd | ply | las")->capture_default_str();
  cmd->add_option("--pcd-data", o->pcd_data, "PCD data: binary | binary_compressed")->capture_default_str();
  cmd->add_option("--out", o->out, "Output folder (one file per sweep: sweep_NNNNNN.pcd)")->required();
  cmd->add_option("--channel", o->channel, "The points_t channel (an LCM log)")->capture_default_str();
  cmd->add_option("--config", o->config,
                  "trajroid.yaml: its global_frame.origin for LAS; a run folder's pipeline (default: the folder's)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--origin", o->origin, "LAT LON HEIGHT of the global frame's origin (LAS), instead of --config")
      ->expected(3)
      ->delimiter(',');
  cmd->add_flag("--accumulate", o->accumulate, "One map of every sweep (map.pcd) instead of a file per sweep");
  cmd->add_option("--voxel", o->voxel_m, "With --accumulate: keep one point per cube of this size, m (0: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--quiet", o->quiet, "No progress lines");
  cmd->callback([o] { run_export(*o); });
}

}  // namespace trajroi::cli
