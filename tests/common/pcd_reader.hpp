#pragma once

// A reader for binary PCD files (the Point Cloud Library's format) as reference decoders
// write them: ASCII header (FIELDS, SIZE, TYPE, COUNT, POINTS, DATA binary) then packed
// records. Test-only; throws std::runtime_error on anything it does not understand.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace trajroi::test {

class PcdCloud {
 public:
  struct Field {
    std::string name;
    std::size_t size = 0;
    char type = 'F';  // F float, U unsigned, I signed
    std::size_t offset = 0;
  };

  [[nodiscard]] std::size_t points() const { return points_; }

  [[nodiscard]] std::vector<float> floats(const std::string& name) const {
    const Field& f = field(name);
    if (f.type != 'F' || f.size != 4) throw std::runtime_error("PCD field " + name + " is not F4");
    std::vector<float> out(points_);
    for (std::size_t i = 0; i < points_; ++i)
      std::memcpy(&out[i], record(i) + f.offset, 4);
    return out;
  }

  [[nodiscard]] std::vector<std::uint32_t> unsigneds(const std::string& name) const {
    const Field& f = field(name);
    if (f.type != 'U' || f.size > 4) throw std::runtime_error("PCD field " + name + " is not U1/U2/U4");
    std::vector<std::uint32_t> out(points_);
    for (std::size_t i = 0; i < points_; ++i) {
      std::uint32_t v = 0;
      for (std::size_t b = 0; b < f.size; ++b)
        v |= static_cast<std::uint32_t>(record(i)[f.offset + b]) << (8 * b);
      out[i] = v;
    }
    return out;
  }

 private:
  friend PcdCloud read_pcd(const std::filesystem::path& path);
  const Field& field(const std::string& name) const {
    for (const Field& f : fields_) {
      if (f.name == name) return f;
    }
    throw std::runtime_error("PCD has no field " + name);
  }
  const std::uint8_t* record(std::size_t i) const { return data_.data() + i * record_bytes_; }

  std::vector<Field> fields_;
  std::size_t record_bytes_ = 0;
  std::size_t points_ = 0;
  std::vector<std::uint8_t> data_;
};

inline PcdCloud read_pcd(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  PcdCloud cloud;
  std::string line;
  std::vector<std::string> names, types;
  std::vector<std::size_t> sizes;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "FIELDS") {
      for (std::string w; words >> w;)
        names.push_back(w);
    } else if (key == "SIZE") {
      for (std::size_t w; words >> w;)
        sizes.push_back(w);
    } else if (key == "TYPE") {
      for (std::string w; words >> w;)
        types.push_back(w);
    } else if (key == "COUNT") {
      for (std::size_t w; words >> w;) {
        if (w != 1) throw std::runtime_error(path.string() + ": PCD COUNT other than 1");
      }
    } else if (key == "POINTS") {
      words >> cloud.points_;
    } else if (key == "DATA") {
      std::string kind;
      words >> kind;
      if (kind != "binary") throw std::runtime_error(path.string() + ": PCD DATA " + kind + " not supported");
      break;
    }
  }
  if (names.empty() || names.size() != sizes.size() || names.size() != types.size()) {
    throw std::runtime_error(path.string() + ": PCD header incomplete");
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    cloud.fields_.push_back({names[i], sizes[i], types[i].at(0), cloud.record_bytes_});
    cloud.record_bytes_ += sizes[i];
  }
  cloud.data_.resize(cloud.points_ * cloud.record_bytes_);
  in.read(reinterpret_cast<char*>(cloud.data_.data()), static_cast<std::streamsize>(cloud.data_.size()));
  if (static_cast<std::size_t>(in.gcount()) != cloud.data_.size()) {
    throw std::runtime_error(path.string() + ": PCD data shorter than POINTS × record size");
  }
  return cloud;
}

}  // namespace trajroi::test
