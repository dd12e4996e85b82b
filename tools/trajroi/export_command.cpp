// trajroi export: trajroid's kept points from an LCM log into files other tools open (PCD, PLY),
// one per sweep or one accumulated map. Other channels and types are skipped and counted; a log
// cut short is exported up to the cut, which is named, and the command then fails.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include "commands.hpp"
#include "file_io.hpp"
#include "trajroi/cloud_io/cloud.hpp"
#include "trajroi/cloud_io/pcd.hpp"
#include "trajroi/cloud_io/ply.hpp"
#include "trajroi/points_t.hpp"
#include "trajroi/transport/lcm_log.hpp"

namespace trajroi::cli {

namespace {

namespace fs = std::filesystem;

struct ExportOptions {
  std::string source;
  std::string format = "pcd";
  std::string pcd_data = "binary";
  std::string out;
  std::string channel = "TRAJROI_POINTS";
  bool accumulate = false;
  double voxel_m = 0.0;
  bool quiet = false;
};

std::vector<std::uint8_t> encode(const cloud_io::Cloud& cloud, const ExportOptions& o) {
  if (o.format == "ply") return cloud_io::encode_ply(cloud);
  return cloud_io::encode_pcd(cloud, cloud_io::pcd_data_from(o.pcd_data));
}

void write(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  write_file_atomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

void run_export(const ExportOptions& o) {
  if (o.format != "pcd" && o.format != "ply")
    throw std::runtime_error("--format " + o.format + ": pcd or ply (las: not yet)");
  (void)cloud_io::pcd_data_from(o.pcd_data);  // checked before anything is written
  std::ifstream in(o.source, std::ios::binary);
  if (!in) throw std::runtime_error(o.source + ": cannot open");
  const auto total = static_cast<double>(fs::file_size(o.source));
  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) throw std::runtime_error(o.out + ": cannot create the output folder: " + ec.message());

  transport::LcmLogReader reader(in);
  transport::LcmLogEvent event;
  cloud_io::Accumulator map(o.voxel_m);
  std::uint64_t exported = 0, points = 0, other_channels = 0, not_points = 0;
  auto last_progress = std::chrono::steady_clock::now();
  transport::LcmLogReader::Next next;
  while ((next = reader.next(event)) == transport::LcmLogReader::Next::kEvent) {
    if (event.channel != o.channel) {
      ++other_channels;
      continue;
    }
    trajroi::points_t m;
    if (m.decode(event.data.data(), 0, static_cast<int>(event.data.size())) != static_cast<int>(event.data.size())) {
      ++not_points;  // another type on the channel, or a damaged message
      continue;
    }
    if (o.accumulate) {
      map.add(m);
    } else {
      char name[48];
      std::snprintf(name, sizeof name, "sweep_%06lld.%s", static_cast<long long>(m.sweep_index), o.format.c_str());
      write(fs::path(o.out) / name, encode(cloud_io::from_points(m), o));
    }
    ++exported;
    points += static_cast<std::uint64_t>(m.num_points);
    const auto now = std::chrono::steady_clock::now();
    if (!o.quiet && now - last_progress > std::chrono::seconds(1)) {
      std::fprintf(stderr, "trajroi export: %.0f %% of %s, %llu sweeps\n",
                   100.0 * static_cast<double>(reader.event_offset()) / total, o.source.c_str(),
                   static_cast<unsigned long long>(exported));
      last_progress = now;
    }
  }
  std::uint64_t written = points;
  if (o.accumulate && exported > 0) {
    written = map.cloud().size();
    write(fs::path(o.out) / ("map." + o.format), encode(map.cloud(), o));
  }
  std::printf(
      "trajroi export: %llu sweeps, %llu points %s %s in %s; skipped %llu events of other channels and %llu "
      "messages on %s that are not points_t; %llu bytes skipped between events\n",
      static_cast<unsigned long long>(exported), static_cast<unsigned long long>(written),
      o.accumulate ? "(the map)" : "", o.format.c_str(), o.out.c_str(), static_cast<unsigned long long>(other_channels),
      static_cast<unsigned long long>(not_points), o.channel.c_str(),
      static_cast<unsigned long long>(reader.skipped_bytes()));
  if (next == transport::LcmLogReader::Next::kCut) {
    throw std::runtime_error(o.source + ": cut short: its last event, from byte " +
                             std::to_string(reader.event_offset()) + ", is incomplete; the " +
                             std::to_string(exported) + " sweeps before it are exported");
  }
  if (exported == 0) throw std::runtime_error(o.source + ": no points_t on " + o.channel + " (--channel)");
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export", "Write trajroid's kept points from an LCM log (lcm-logger, or a file:// LCM URL) as PCD or PLY files");
  cmd->add_option("source", o->source, "LCM log")->required()->check(CLI::ExistingFile);
  cmd->add_option("--format", o->format, "pcd | ply")->capture_default_str();
  cmd->add_option("--pcd-data", o->pcd_data, "PCD data: binary | binary_compressed")->capture_default_str();
  cmd->add_option("--out", o->out, "Output folder (one file per sweep: sweep_NNNNNN.pcd)")->required();
  cmd->add_option("--channel", o->channel, "The points_t channel")->capture_default_str();
  cmd->add_flag("--accumulate", o->accumulate, "One map of every sweep (map.pcd) instead of a file per sweep");
  cmd->add_option("--voxel", o->voxel_m, "With --accumulate: keep one point per cube of this size, m (0: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--quiet", o->quiet, "No progress lines");
  cmd->callback([o] { run_export(*o); });
}

}  // namespace trajroi::cli
