#include "trajroi/cloud_io/ply.hpp"

#include <bit>
#include <string>

namespace trajroi::cloud_io {

static_assert(std::endian::native == std::endian::little, "binary_little_endian is written as the host stores it");

std::vector<std::uint8_t> encode_ply(const Cloud& c) {
  std::string comment = c.comment;
  for (char& ch : comment)
    if (ch == '\n' || ch == '\r') ch = ' ';
  const std::string head = "ply\nformat binary_little_endian 1.0\ncomment " + comment + "\nelement vertex " +
                           std::to_string(c.size()) +
                           "\nproperty float x\nproperty float y\nproperty float z\nproperty float intensity\n"
                           "property ushort ring\nproperty float time\nproperty uchar return_type\nend_header\n";
  std::vector<std::uint8_t> out(head.begin(), head.end());
  out.reserve(out.size() + c.size() * 23);
  const auto put = [&out](const auto& value) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    out.insert(out.end(), p, p + sizeof(value));
  };
  for (std::size_t i = 0; i < c.size(); ++i) {
    put(c.x[i]);
    put(c.y[i]);
    put(c.z[i]);
    put(c.intensity[i]);
    put(c.ring[i]);
    put(c.time_s[i]);
    put(c.return_type[i]);
  }
  return out;
}

}  // namespace trajroi::cloud_io
