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

// "source:LINE" for a node (yaml-cpp counts lines from 0).
std::string at(std::string_view source, const YAML::Node& node) {
  return std::string(source) + ":" + std::to_string(node.Mark().line + 1);
}

double read_number(const YAML::Node& laser, const char* key, std::string_view source, std::size_t index,
                   bool required) {
  const YAML::Node value = laser[key];
  if (!value) {
    if (required) fail(at(source, laser), "laser entry " + std::to_string(index) + " has no '" + key + "'");
    return 0.0;
  }
  double number = 0.0;
  try {
    number = value.as<double>();
  } catch (const YAML::Exception&) {
    fail(at(source, value), "laser entry " + std::to_string(index) + ": '" + key + "' is not a number");
  }
  if (!std::isfinite(number)) {
    fail(at(source, value), "laser entry " + std::to_string(index) + ": '" + key + "' is not finite");
  }
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
  const std::size_t n = lasers.size();
  if (n != 16 && n != kMaxLasers) {
    fail(at(source, lasers), "'lasers' has " + std::to_string(n) + " entries; the models trajroi decodes have 16 " +
                                 "(VLP-16, Puck LITE, Puck Hi-Res) or 32 (VLP-32C, HDL-32E)");
  }
  if (const YAML::Node count = root["num_lasers"]) {
    double declared = 0.0;
    try {
      declared = count.as<double>();
    } catch (const YAML::Exception&) {
      fail(at(source, count), "'num_lasers' is not a number");
    }
    if (declared != static_cast<double>(n)) {
      fail(at(source, count),
           "'num_lasers' says " + count.as<std::string>() + " but 'lasers' has " + std::to_string(n) + " entries");
    }
  }
  Calibration calibration;
  calibration.laser_count = n;
  std::bitset<kMaxLasers> seen;
  for (std::size_t i = 0; i < n; ++i) {
    const YAML::Node laser = lasers[i];
    if (!laser.IsMap()) fail(at(source, laser), "laser entry " + std::to_string(i) + " is not a map");
    const double id = read_number(laser, "laser_id", source, i, true);
    if (id < 0 || id >= static_cast<double>(n) || id != std::floor(id)) {
      fail(at(source, laser), "laser entry " + std::to_string(i) + ": laser_id " + std::to_string(id) + " is not 0 … " +
                                  std::to_string(n - 1));
    }
    const auto index = static_cast<std::size_t>(id);
    if (seen[index]) fail(at(source, laser), "laser_id " + std::to_string(index) + " appears twice");
    seen[index] = true;
    LaserCalibration& cal = calibration.lasers[index];
    cal.vert_angle_rad = read_number(laser, "vert_correction", source, i, true);
    if (std::abs(cal.vert_angle_rad) > 0.5 * std::numbers::pi) {
      fail(at(source, laser), "laser_id " + std::to_string(index) + ": vert_correction is not an angle in radians");
    }
    cal.rot_correction_rad = read_number(laser, "rot_correction", source, i, false);
    cal.vert_offset_m = read_number(laser, "vert_offset_correction", source, i, false);
    cal.horiz_offset_m = read_number(laser, "horiz_offset_correction", source, i, false);
    cal.dist_correction_m = read_number(laser, "dist_correction", source, i, false);
  }
  return calibration;
}

}  // namespace trajroi::vlp16
