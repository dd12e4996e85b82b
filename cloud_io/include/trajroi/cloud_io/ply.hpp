#pragma once

// PLY (Stanford polygon format), binary little endian, one vertex element with the properties
//   float x y z intensity, ushort ring, float time (s), uchar return_type
// as PCL, Open3D, CloudCompare and MeshLab read it.
#include <cstdint>
#include <vector>

#include "trajroi/cloud_io/cloud.hpp"

namespace trajroi::cloud_io {

[[nodiscard]] std::vector<std::uint8_t> encode_ply(const Cloud& cloud);

}  // namespace trajroi::cloud_io
