#pragma once

// LAS 1.4 (ASPRS, R15), point data record format 6, georeferenced: what mapping tools
// (CloudCompare, PDAL, QGIS, LAStools) place on the map. The cloud's global-frame points (ENU
// about the configured origin) are projected to UTM in the origin's zone (WGS 84, GeographicLib;
// z: height above the ellipsoid), its CRS written as OGC WKT (the LASF_Projection VLR 2112,
// global encoding bit 4). Per point: X Y Z at 1 mm, intensity (reflectivity × 257: 0–255 over
// the 16 bits), return number and count (dual return: strongest-only 1 of 2, last-only 2 of 2;
// both and single-return modes 1 of 1), user data = ring, GPS time (adjusted standard GPS time,
// global encoding bit 0, when the cloud's UTC is known; else seconds after its start, bit 0
// clear). Pure: numbers in, bytes out.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "trajroi/cloud_io/cloud.hpp"

namespace GeographicLib {
class LocalCartesian;
}

namespace trajroi::cloud_io {

// The global frame's origin and the UTM zone the export projects into (the origin's).
class UtmProjection {
 public:
  // Throws std::invalid_argument for an origin outside UTM's latitudes (84° N … 80° S).
  UtmProjection(double lat_deg, double lon_deg, double height_m);
  ~UtmProjection();
  UtmProjection(UtmProjection&&) noexcept;
  struct Projected {
    double easting_m, northing_m, height_m;  // height above the WGS 84 ellipsoid
  };
  // A global-frame point (x east, y north, z up, m, about the origin) in UTM.
  [[nodiscard]] Projected project(double x_m, double y_m, double z_m) const;
  [[nodiscard]] int zone() const noexcept { return zone_; }
  [[nodiscard]] bool northern() const noexcept { return northern_; }
  [[nodiscard]] int epsg() const noexcept { return (northern_ ? 32600 : 32700) + zone_; }
  // "WGS 84 / UTM zone 32N" as OGC WKT (version 1), with its EPSG authority.
  [[nodiscard]] std::string wkt() const;

 private:
  std::unique_ptr<GeographicLib::LocalCartesian> frame_;  // the global frame (ENU about the origin)
  int zone_ = 0;
  bool northern_ = true;
};

struct LasHeaderText {
  std::string system_identifier = "trajroi export";
  std::string generating_software = "trajroi";
  int creation_day_of_year = 1;  // 1 … 366
  int creation_year = 2026;
};

// GPS − UTC at a UTC instant (ns since 1970): the leap seconds since 1980-01-06.
[[nodiscard]] int gps_minus_utc_s(std::int64_t utc_ns) noexcept;

[[nodiscard]] std::vector<std::uint8_t> encode_las(const Cloud& cloud, const UtmProjection& utm,
                                                   const LasHeaderText& text);

inline constexpr std::size_t kLasHeaderSize = 375;
inline constexpr std::size_t kLasPointFormat6Size = 30;

}  // namespace trajroi::cloud_io
