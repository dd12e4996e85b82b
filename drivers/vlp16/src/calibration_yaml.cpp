// The velodyne/nebula calibration YAML, read with yaml-cpp.
#include <yaml-cpp/yaml.h>

#include <bitset>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "trajroi/vlp16/decoder.hpp"

namespace trajroi::vlp16 {
namespace {

[[noreturn]] void fail(std::string_view source, const std::string& what) {
  throw std::runtime_error(std::string(source) + ": " + what);
}

double read_number(const YAML::Node& laser, const char* key, std::string_view source, std::size_t index,
                   bool required) {
  const YAML::Node value = laser[key];
  if (!value) {
    if (required) fail(source, "laser entry " + std::to_string(index) + " has no '" + key + "'");
    return 0.0;
  }
  double number = 0.0;
  try {
    number = value.as<double>();
  } catch (const YAML::Exception&) {
    fail(source, "laser entry " + std::to_string(index) + ": '" + key + "' is not a number");
  }
  if (!std::isfinite(number)) fail(source, "laser entry " + std::to_string(index) + ": '" + key + "' is not finite");
  return number;
}

}  // namespace

Calibration parse_calibration_yaml(std::string_view text, std::string_view source) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    fail(source, "line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  const YAML::Node lasers = root["lasers"];
  if (!lasers || !lasers.IsSequence()) fail(source, "no 'lasers' list");
  if (lasers.size() != kLasers) {
    fail(source, "'lasers' has " + std::to_string(lasers.size()) + " entries; a VLP-16 has 16");
  }
  Calibration calibration;
  std::bitset<kLasers> seen;
  for (std::size_t i = 0; i < lasers.size(); ++i) {
    const YAML::Node laser = lasers[i];
    if (!laser.IsMap()) fail(source, "laser entry " + std::to_string(i) + " is not a map");
    const double id = read_number(laser, "laser_id", source, i, true);
    if (id < 0 || id >= static_cast<double>(kLasers) || id != std::floor(id)) {
      fail(source, "laser entry " + std::to_string(i) + ": laser_id " + std::to_string(id) + " is not 0 … 15");
    }
    const auto index = static_cast<std::size_t>(id);
    if (seen[index]) fail(source, "laser_id " + std::to_string(index) + " appears twice");
    seen[index] = true;
    LaserCalibration& cal = calibration.lasers[index];
    cal.vert_angle_rad = read_number(laser, "vert_correction", source, i, true);
    if (std::abs(cal.vert_angle_rad) > 0.5 * std::numbers::pi) {
      fail(source, "laser_id " + std::to_string(index) + ": vert_correction is not an angle in radians");
    }
    cal.rot_correction_rad = read_number(laser, "rot_correction", source, i, false);
    cal.vert_offset_m = read_number(laser, "vert_offset_correction", source, i, false);
    cal.horiz_offset_m = read_number(laser, "horiz_offset_correction", source, i, false);
    cal.dist_correction_m = read_number(laser, "dist_correction", source, i, false);
  }
  return calibration;
}

}  // namespace trajroi::vlp16
