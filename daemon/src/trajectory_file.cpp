#include "trajroi/daemon/trajectory_file.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "trajroi/config/text_file.hpp"
#include "trajroi/pose/geodetic.hpp"

namespace trajroi::daemon {

namespace {

std::string lower_without_spaces(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (std::isspace(static_cast<unsigned char>(c)) == 0)
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

// The first line that is neither empty nor a comment, and where it ends.
std::string_view first_content_line(std::string_view text, std::size_t& end) {
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t stop = text.find('\n', at);
    if (stop == std::string_view::npos) stop = text.size();
    std::string_view line = text.substr(at, stop - at);
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    end = stop;
    if (!lower_without_spaces(line).empty()) return line;
    at = stop + 1;
  }
  end = text.size();
  return {};
}

std::string format_degrees(double a, double b) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6f, %.6f", a, b);
  return text;
}

}  // namespace

roi::Trajectory parse_trajectory(std::string_view text, const TrajectorySource& source) {
  const std::string name = source.file.string();
  TrajectoryCoordinates coordinates = source.coordinates;
  std::size_t header_end = 0;
  const std::string header = lower_without_spaces(first_content_line(text, header_end));
  std::string body(text);
  if (header == "x,y" || header == "x_m,y_m") {
    coordinates = TrajectoryCoordinates::kGlobalXy;
    body.replace(0, header_end, std::string(header_end, ' '));  // keep the line numbers
  } else if (header == "lat,lon" || header == "lat_deg,lon_deg") {
    coordinates = TrajectoryCoordinates::kLatLon;
    body.replace(0, header_end, std::string(header_end, ' '));
  }
  // Both are read as pairs first; the library checks the numbers and names bad lines.
  roi::Trajectory pairs = roi::parse_trajectory_csv(body, name);
  if (coordinates == TrajectoryCoordinates::kGlobalXy) {
    bool all_near_origin_degrees = true;
    for (const Eigen::Vector2d& w : pairs.waypoints()) {
      const bool lat_lon =
          std::abs(w.x() - source.origin.lat_deg) < 1.0 && std::abs(w.y() - source.origin.lon_deg) < 1.0;
      const bool lon_lat =
          std::abs(w.x() - source.origin.lon_deg) < 1.0 && std::abs(w.y() - source.origin.lat_deg) < 1.0;
      all_near_origin_degrees = all_near_origin_degrees && (lat_lon || lon_lat);
    }
    if (all_near_origin_degrees && !(std::abs(source.origin.lat_deg) < 1.0 && std::abs(source.origin.lon_deg) < 1.0)) {
      const Eigen::Vector2d& w = pairs.waypoints().front();
      throw std::runtime_error(name + ": the waypoints (first " + format_degrees(w.x(), w.y()) +
                               ") look like degrees near the origin (" +
                               format_degrees(source.origin.lat_deg, source.origin.lon_deg) +
                               "), read as metres; start the file with a 'lat,lon' line or set "
                               "trajectory.coordinates: lat_lon");
    }
    return pairs;
  }
  const pose::GlobalFrame frame = pose::GlobalFrame::local_cartesian(source.origin);
  std::vector<Eigen::Vector2d> global;
  global.reserve(pairs.waypoints().size());
  for (const Eigen::Vector2d& w : pairs.waypoints()) {
    if (!(std::abs(w.x()) <= 90.0) || !(std::abs(w.y()) <= 180.0)) {
      throw std::runtime_error(name + ": waypoint " + format_degrees(w.x(), w.y()) +
                               " is not a latitude, longitude in degrees (|lat| <= 90, |lon| <= 180)");
    }
    global.push_back(frame.to_global(pose::Geodetic{w.x(), w.y(), source.origin.height_m}).head<2>());
  }
  try {
    return roi::Trajectory(std::move(global));
  } catch (const roi::TrajectoryError& e) {
    throw roi::TrajectoryError(e.code(), name + ": " + e.what());
  }
}

std::unique_ptr<pipeline::ActiveTrajectory> load_trajectory(const TrajectorySource& source) {
  return std::make_unique<pipeline::ActiveTrajectory>(
      pipeline::ActiveTrajectory{parse_trajectory(config::read_text_file(source.file), source), 0});
}

}  // namespace trajroi::daemon
