#include "trajroi/config/text_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "trajroi/config/yaml_reader.hpp"

namespace trajroi::config {

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path.string() + ": cannot be read: " + std::strerror(errno));
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw ConfigError(path.string() + ": read error");
  return std::move(content).str();
}

}  // namespace trajroi::config
