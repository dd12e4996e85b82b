#include "trajroi/cloud_io/pcd.hpp"

#include <bit>
#include <stdexcept>
#include <string>

#include "trajroi/cloud_io/lzf.hpp"

namespace trajroi::cloud_io {

namespace {

static_assert(std::endian::native == std::endian::little, "PCD binary data is written as the host stores it");

template <typename T>
void put(std::vector<std::uint8_t>& out, const T& value) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

template <typename T>
void put_all(std::vector<std::uint8_t>& out, const std::vector<T>& values) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(values.data());
  out.insert(out.end(), p, p + values.size() * sizeof(T));
}

std::string header(const Cloud& c, const char* data) {
  const std::string n = std::to_string(c.size());
  std::string comment = c.comment;
  for (char& ch : comment)
    if (ch == '\n' || ch == '\r') ch = ' ';
  return "# .PCD v0.7 - Point Cloud Data file format\n# " + comment +
         "\nVERSION 0.7\nFIELDS x y z intensity ring time return_type\nSIZE 4 4 4 4 2 4 1\nTYPE F F F F U F U\n"
         "COUNT 1 1 1 1 1 1 1\nWIDTH " +
         n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA " + data + "\n";
}

}  // namespace

PcdData pcd_data_from(std::string_view name) {
  if (name == "binary") return PcdData::kBinary;
  if (name == "binary_compressed") return PcdData::kBinaryCompressed;
  throw std::invalid_argument("PCD data '" + std::string(name) + "': binary or binary_compressed");
}

std::vector<std::uint8_t> encode_pcd(const Cloud& c, PcdData data) {
  const std::string head = header(c, data == PcdData::kBinary ? "binary" : "binary_compressed");
  std::vector<std::uint8_t> out(head.begin(), head.end());
  const std::size_t n = c.size();
  if (data == PcdData::kBinary) {
    out.reserve(out.size() + n * 23);
    for (std::size_t i = 0; i < n; ++i) {
      put(out, c.x[i]);
      put(out, c.y[i]);
      put(out, c.z[i]);
      put(out, c.intensity[i]);
      put(out, c.ring[i]);
      put(out, c.time_s[i]);
      put(out, c.return_type[i]);
    }
    return out;
  }
  std::vector<std::uint8_t> fields;
  fields.reserve(n * 23);
  put_all(fields, c.x);
  put_all(fields, c.y);
  put_all(fields, c.z);
  put_all(fields, c.intensity);
  put_all(fields, c.ring);
  put_all(fields, c.time_s);
  put_all(fields, c.return_type);
  const std::vector<std::uint8_t> packed = lzf_compress(fields);
  put(out, static_cast<std::uint32_t>(packed.size()));
  put(out, static_cast<std::uint32_t>(fields.size()));
  out.insert(out.end(), packed.begin(), packed.end());
  return out;
}

}  // namespace trajroi::cloud_io
