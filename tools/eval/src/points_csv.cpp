#include "trajroi/eval/points_csv.hpp"

#include <stdexcept>
#include <string>

#include "trajroi/roi/text.hpp"

namespace trajroi::eval {

std::vector<roi::PointXYZd> parse_points_csv(std::string_view text, std::string_view source_name) {
  std::vector<roi::PointXYZd> points;
  std::size_t line_number = 0;
  roi::for_each_line(text, [&](std::string_view line) {
    ++line_number;
    const std::string_view content = roi::strip_comment_and_space(line);
    if (content.empty()) return;
    double values[4];
    const std::size_t fields = roi::parse_csv_doubles(content, values);
    if (fields != 3 && fields != 4) {
      throw std::runtime_error(std::string(source_name) + ":" + std::to_string(line_number) +
                               ": expected 'x,y,z[,intensity]', got '" + std::string(content) + "'");
    }
    points.push_back({values[0], values[1], values[2]});
  });
  return points;
}

}  // namespace trajroi::eval
