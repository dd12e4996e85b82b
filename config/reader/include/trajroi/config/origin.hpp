#pragma once

// The global frame's origin block (`origin: {lat_deg, lon_deg, height_m}`), read the same way
// by the daemon's configuration and the simulator's scenarios: latitude within ±90°,
// longitude within ±180°, height above the WGS84 ellipsoid (default 0). The local tangent
// plane about it is defined at every latitude, so no tighter bound is needed.
#include "trajroi/config/yaml_reader.hpp"

namespace trajroi::config {

struct Origin {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double height_m = 0.0;
};

// Reads and finishes the block; throws ConfigError naming the key and value.
[[nodiscard]] Origin read_origin(MapReader origin);

}  // namespace trajroi::config
