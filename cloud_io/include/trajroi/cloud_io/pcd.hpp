#pragma once

// PCD v0.7 (PCL's point cloud format) as PCL, Open3D and CloudCompare read it: fields
//   x y z intensity (float32)  ring (uint16)  time (float32, s)  return_type (uint8)
// in one unorganised row (HEIGHT 1), DATA binary (one record per point, little endian) or
// binary_compressed (the fields one after another, LZF-compressed, after their two sizes).
#include <cstdint>
#include <string_view>
#include <vector>

#include "trajroi/cloud_io/cloud.hpp"

namespace trajroi::cloud_io {

enum class PcdData : std::uint8_t { kBinary, kBinaryCompressed };
[[nodiscard]] PcdData pcd_data_from(std::string_view name);  // "binary" | "binary_compressed"

[[nodiscard]] std::vector<std::uint8_t> encode_pcd(const Cloud& cloud, PcdData data);

}  // namespace trajroi::cloud_io
