#include "file_io.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace trajroi::cli {

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  std::filesystem::path temporary = path;
  temporary += ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw std::runtime_error(temporary.string() + ": cannot create: " + std::strerror(errno));
    }
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) {
      std::filesystem::remove(temporary);
      throw std::runtime_error(temporary.string() + ": write error");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary);
    throw std::runtime_error(path.string() + ": cannot write: " + ec.message());
  }
}

}  // namespace trajroi::cli
