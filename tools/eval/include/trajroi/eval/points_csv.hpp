#pragma once

#include <string_view>
#include <vector>

#include "trajroi/roi/point.hpp"

namespace trajroi::eval {

// Parses points from CSV text, one `x,y,z[,intensity]` per line (metres; intensity read and
// ignored), blank lines and `#` comments skipped. Non-finite values parse ("nan", "inf") so
// the filters can count them. Throws std::runtime_error "<source>:<line>: …" otherwise.
[[nodiscard]] std::vector<roi::PointXYZd> parse_points_csv(std::string_view text, std::string_view source_name);

}  // namespace trajroi::eval
