// VeloView's calibration XML (Velodyne's db.xml form, a boost serialization archive): under
// <DB><points_>, one <item><px> per laser with <id_>, <rotCorrection_> and <vertCorrection_>
// (degrees), <distCorrection_>, <vertOffsetCorrection_> and <horizOffsetCorrection_>
// (centimetres), as the ROS velodyne driver's gen_calibration.py reads them. Only these
// elements are read; the rest of the archive is skipped. Pure.
#include <bitset>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "trajroi/vlp16/decoder.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// before + text + after, built by appending (GCC 12 warns falsely on some operator+ chains).
std::string wrapped(std::string_view before, std::string_view text, std::string_view after) {
  std::string s;
  s.reserve(before.size() + text.size() + after.size());
  s.append(before).append(text).append(after);
  return s;
}

class XmlText {
 public:
  XmlText(std::string_view text, std::string_view source) : text_(text), source_(source) {}

  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    std::size_t line = 1;
    for (std::size_t i = 0; i < at && i < text_.size(); ++i)
      if (text_[i] == '\n') ++line;
    throw std::runtime_error(std::string(source_) + ":" + std::to_string(line) + ": " + what);
  }
  // The position of `<tag>` (or `<tag ` with attributes) at or after `from`, before `end`.
  [[nodiscard]] std::size_t find_open(std::string_view tag, std::size_t from, std::size_t end) const {
    const std::string needle = wrapped("<", tag, "");
    for (std::size_t at = text_.find(needle, from); at != std::string_view::npos && at < end;
         at = text_.find(needle, at + 1)) {
      const std::size_t after = at + 1 + tag.size();
      if (after < text_.size() && (text_[after] == '>' || text_[after] == ' ')) return at;
    }
    return std::string_view::npos;
  }
  // The content between `<tag…>` at `open` and its `</tag>`.
  [[nodiscard]] std::pair<std::size_t, std::size_t> content(std::string_view tag, std::size_t open) const {
    const std::size_t start = text_.find('>', open);
    const std::size_t close = text_.find(wrapped("</", tag, ">"), open);
    if (start == std::string_view::npos || close == std::string_view::npos)
      fail(open, wrapped("<", tag, "> is not closed"));
    return {start + 1, close};
  }
  // The number in <tag> inside [from, end).
  [[nodiscard]] double number(std::string_view tag, std::size_t from, std::size_t end, std::size_t laser_entry) const {
    const std::size_t open = find_open(tag, from, end);
    if (open == std::string_view::npos) {
      fail(from, "laser entry " + std::to_string(laser_entry) + " has no " + wrapped("<", tag, ">"));
    }
    const auto [begin, stop] = content(tag, open);
    std::string_view s = text_.substr(begin, stop - begin);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0)
      s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0)
      s.remove_suffix(1);
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) {
      fail(open, "laser entry " + std::to_string(laser_entry) + ": " + wrapped("<", tag, "> '") + std::string(s) +
                     "' is not a number");
    }
    return v;
  }
  [[nodiscard]] std::string_view text() const noexcept { return text_; }

 private:
  std::string_view text_;
  std::string_view source_;
};

}  // namespace

bool looks_like_calibration_xml(std::string_view text) noexcept {
  return text.find("<boost_serialization") != std::string_view::npos || text.find("<?xml") != std::string_view::npos;
}

Calibration parse_calibration_xml(std::string_view text, std::string_view source) {
  const XmlText xml(text, source);
  const std::size_t points = xml.find_open("points_", 0, text.size());
  if (points == std::string_view::npos)
    xml.fail(0, "no <points_> (a VeloView / db.xml calibration holds the lasers there)");
  const auto [begin, end] = xml.content("points_", points);
  std::vector<std::pair<std::size_t, std::size_t>> entries;  // each <px>'s content
  for (std::size_t at = xml.find_open("px", begin, end); at != std::string_view::npos;
       at = xml.find_open("px", at + 1, end)) {
    entries.push_back(xml.content("px", at));
  }
  const std::size_t n = entries.size();
  if (n != 16 && n != kMaxLasers) {
    xml.fail(points, "<points_> holds " + std::to_string(n) +
                         " lasers; the models trajroi decodes have 16 (VLP-16, Puck LITE, Puck Hi-Res) or 32 "
                         "(VLP-32C, HDL-32E)");
  }
  Calibration calibration;
  calibration.laser_count = n;
  std::bitset<kMaxLasers> seen;
  for (std::size_t i = 0; i < n; ++i) {
    const auto [from, stop] = entries[i];
    const double id = xml.number("id_", from, stop, i);
    if (id < 0 || id >= static_cast<double>(n) || id != std::floor(id)) {
      xml.fail(from, "laser entry " + std::to_string(i) + ": <id_> " + std::to_string(id) + " is not 0 … " +
                         std::to_string(n - 1));
    }
    const auto index = static_cast<std::size_t>(id);
    if (seen[index]) xml.fail(from, "laser id " + std::to_string(index) + " appears twice");
    seen[index] = true;
    LaserCalibration& cal = calibration.lasers[index];
    const double vertical_deg = xml.number("vertCorrection_", from, stop, i);
    if (std::abs(vertical_deg) > 90.0)
      xml.fail(from, "laser id " + std::to_string(index) + ": <vertCorrection_> is not an angle in degrees");
    cal.vert_angle_rad = vertical_deg * kDegToRad;
    cal.rot_correction_rad = xml.number("rotCorrection_", from, stop, i) * kDegToRad;
    cal.dist_correction_m = xml.number("distCorrection_", from, stop, i) / 100.0;
    cal.vert_offset_m = xml.number("vertOffsetCorrection_", from, stop, i) / 100.0;
    cal.horiz_offset_m = xml.number("horizOffsetCorrection_", from, stop, i) / 100.0;
  }
  return calibration;
}

Calibration parse_calibration_file(std::string_view text, std::string_view source) {
  return looks_like_calibration_xml(text) ? parse_calibration_xml(text, source) : parse_calibration_yaml(text, source);
}

}  // namespace trajroi::vlp16
