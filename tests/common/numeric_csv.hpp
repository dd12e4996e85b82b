#pragma once

// A numeric CSV (one header line, then numbers separated by commas; blank cells and trailing
// commas ignored), as the VN-100 author's reference files and `trajroi imu-dump --csv` write.
#include <sstream>
#include <string>
#include <vector>

namespace trajroi::test {

inline std::vector<std::vector<double>> read_numeric_csv(const std::string& text,
                                                         std::vector<std::string>* header = nullptr) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  if (header != nullptr) {
    std::istringstream h(line);
    for (std::string cell; std::getline(h, cell, ',');) {
      const std::size_t first = cell.find_first_not_of(' ');
      if (first != std::string::npos) header->push_back(cell.substr(first));
    }
  }
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) {
      if (cell.find_first_not_of(" \r") != std::string::npos) row.push_back(std::stod(cell));
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace trajroi::test
