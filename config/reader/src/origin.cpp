#include "trajroi/config/origin.hpp"

#include <cmath>

namespace trajroi::config {

Origin read_origin(MapReader origin) {
  Origin o;
  o.lat_deg = origin.number("lat_deg");
  origin.require(std::abs(o.lat_deg) <= 90.0, "lat_deg", "must be in [-90, 90]");
  o.lon_deg = origin.number("lon_deg");
  origin.require(std::abs(o.lon_deg) <= 180.0, "lon_deg", "must be in [-180, 180]");
  o.height_m = origin.number("height_m", 0.0);
  origin.finish();
  return o;
}

}  // namespace trajroi::config
