#include "trajroi/cloud_io/las.hpp"

#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace trajroi::cloud_io {
namespace {

class Writer {
 public:
  explicit Writer(std::vector<std::uint8_t>& out) : out_(out) {}
  template <typename T>
  void put(T v) {
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));  // x86-64 and LAS: little-endian
    out_.insert(out_.end(), b, b + sizeof(T));
  }
  void text(const std::string& s, std::size_t width) {
    for (std::size_t i = 0; i < width; ++i)
      out_.push_back(i < s.size() ? static_cast<std::uint8_t>(s[i]) : 0);
  }
  void zeros(std::size_t n) { out_.insert(out_.end(), n, 0); }

 private:
  std::vector<std::uint8_t>& out_;
};

constexpr double kScale_m = 0.001;
constexpr std::int64_t kGpsEpochUnix_s = 315'964'800;  // 1980-01-06T00:00:00Z
constexpr double kAdjustedStandardOffset_s = 1e9;      // LAS: adjusted standard GPS time = GPS s − 1e9

}  // namespace

UtmProjection::UtmProjection(double lat_deg, double lon_deg, double height_m) {
  if (!(lat_deg < 84.0 && lat_deg >= -80.0) || !(std::abs(lon_deg) <= 180.0))
    throw std::invalid_argument("origin " + std::to_string(lat_deg) + ", " + std::to_string(lon_deg) +
                                ": outside UTM (latitudes 80° S … 84° N)");
  frame_ = std::make_unique<GeographicLib::LocalCartesian>(lat_deg, lon_deg, height_m);
  zone_ = GeographicLib::UTMUPS::StandardZone(lat_deg, lon_deg);
  northern_ = lat_deg >= 0.0;
}

UtmProjection::~UtmProjection() = default;
UtmProjection::UtmProjection(UtmProjection&&) noexcept = default;

UtmProjection::Projected UtmProjection::project(double x_m, double y_m, double z_m) const {
  double lat = 0, lon = 0, h = 0;
  frame_->Reverse(x_m, y_m, z_m, lat, lon, h);
  int zone = 0;
  bool north = true;
  Projected p{};
  GeographicLib::UTMUPS::Forward(lat, lon, zone, north, p.easting_m, p.northing_m, zone_);
  if (north != northern_) p.northing_m += northern_ ? -1e7 : 1e7;  // the origin's hemisphere's false northing
  p.height_m = h;
  return p;
}

std::string UtmProjection::wkt() const {
  const std::string name = "WGS 84 / UTM zone " + std::to_string(zone_) + (northern_ ? "N" : "S");
  const int central_meridian = 6 * zone_ - 183;
  return "PROJCS[\"" + name +
         "\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563,"
         "AUTHORITY[\"EPSG\",\"7030\"]],AUTHORITY[\"EPSG\",\"6326\"]],PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\","
         "\"8901\"]],UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\"9122\"]],AUTHORITY[\"EPSG\",\"4326\"]],"
         "PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\"," +
         std::to_string(central_meridian) +
         "],PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],PARAMETER[\"false_northing\"," +
         (northern_ ? "0" : "10000000") +
         "],UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],AXIS[\"Easting\",EAST],AXIS[\"Northing\",NORTH],"
         "AUTHORITY[\"EPSG\",\"" +
         std::to_string(epsg()) + "\"]]";
}

int gps_minus_utc_s(std::int64_t utc_ns) noexcept {
  // The UTC instants (s since 1970) from which GPS − UTC grew by one second (IERS Bulletin C).
  static constexpr std::int64_t kLeaps[] = {362'793'600,   394'329'600,   425'865'600,  489'024'000,   567'993'600,
                                            631'152'000,   662'688'000,   709'948'800,  741'484'800,   773'020'800,
                                            820'454'400,   867'715'200,   915'148'800,  1'136'073'600, 1'230'768'000,
                                            1'341'100'800, 1'435'708'800, 1'483'228'800};
  const std::int64_t s = utc_ns / 1'000'000'000;
  int n = 0;
  for (const std::int64_t at : kLeaps)
    n += s >= at ? 1 : 0;
  return n;
}

std::vector<std::uint8_t> encode_las(const Cloud& cloud, const UtmProjection& utm, const LasHeaderText& text) {
  const std::size_t n = cloud.size();
  std::vector<UtmProjection::Projected> p(n);
  double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                  std::numeric_limits<double>::max()};
  double hi[3] = {std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest(),
                  std::numeric_limits<double>::lowest()};
  for (std::size_t i = 0; i < n; ++i) {
    p[i] =
        utm.project(static_cast<double>(cloud.x[i]), static_cast<double>(cloud.y[i]), static_cast<double>(cloud.z[i]));
    const double v[3] = {p[i].easting_m, p[i].northing_m, p[i].height_m};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
    }
  }
  if (n == 0) std::fill(lo, lo + 3, 0.0), std::fill(hi, hi + 3, 0.0);
  // Offsets on whole kilometres below the minimum: every coordinate a small positive integer of mm.
  double offset[3];
  for (int k = 0; k < 3; ++k)
    offset[k] = std::floor(lo[k] / 1000.0) * 1000.0;

  const bool utc = cloud.start_utc_ns != 0;
  const double start_s = utc ? static_cast<double>(cloud.start_utc_ns / 1'000'000'000 +
                                                   gps_minus_utc_s(cloud.start_utc_ns) - kGpsEpochUnix_s) -
                                   kAdjustedStandardOffset_s +
                                   static_cast<double>(cloud.start_utc_ns % 1'000'000'000) * 1e-9
                             : 0.0;

  const std::string wkt = utm.wkt();
  const std::size_t vlr_size = 54 + wkt.size() + 1;
  std::vector<std::uint8_t> out;
  out.reserve(kLasHeaderSize + vlr_size + n * kLasPointFormat6Size);
  Writer w(out);
  // ---- public header block (LAS 1.4 R15, Table 3)
  w.text("LASF", 4);
  w.put<std::uint16_t>(0);                                                        // file source id
  w.put<std::uint16_t>(static_cast<std::uint16_t>((utc ? 0x0001 : 0) | 0x0010));  // GPS time type, WKT
  w.zeros(16);                                                                    // project GUID
  w.put<std::uint8_t>(1);
  w.put<std::uint8_t>(4);
  w.text(text.system_identifier, 32);
  w.text(text.generating_software, 32);
  w.put<std::uint16_t>(static_cast<std::uint16_t>(text.creation_day_of_year));
  w.put<std::uint16_t>(static_cast<std::uint16_t>(text.creation_year));
  w.put<std::uint16_t>(static_cast<std::uint16_t>(kLasHeaderSize));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(kLasHeaderSize + vlr_size));  // offset to point data
  w.put<std::uint32_t>(1);                                                      // VLRs
  w.put<std::uint8_t>(6);                                                       // point data record format
  w.put<std::uint16_t>(static_cast<std::uint16_t>(kLasPointFormat6Size));
  w.put<std::uint32_t>(0);  // legacy point count: 0 for formats 6–10
  w.zeros(5 * 4);           // legacy points by return
  for (int k = 0; k < 3; ++k)
    w.put<double>(kScale_m);
  for (int k = 0; k < 3; ++k)
    w.put<double>(offset[k]);
  for (int k = 0; k < 3; ++k) {
    w.put<double>(hi[k]);
    w.put<double>(lo[k]);
  }
  w.put<std::uint64_t>(0);  // start of waveform data
  w.put<std::uint64_t>(0);  // start of the first EVLR
  w.put<std::uint32_t>(0);  // EVLRs
  w.put<std::uint64_t>(n);
  std::uint64_t by_return[15] = {};
  const bool dual = cloud.return_mode == 0x39;
  const auto returns = [dual](std::uint8_t type) -> std::pair<std::uint8_t, std::uint8_t> {
    if (!dual || type == 3) return {1, 1};
    return type == 2 ? std::pair<std::uint8_t, std::uint8_t>{2, 2} : std::pair<std::uint8_t, std::uint8_t>{1, 2};
  };
  for (std::size_t i = 0; i < n; ++i)
    ++by_return[returns(cloud.return_type[i]).first - 1];
  for (const std::uint64_t c : by_return)
    w.put<std::uint64_t>(c);
  // ---- the CRS: OGC WKT (LASF_Projection, record 2112), NUL-terminated
  w.put<std::uint16_t>(0);
  w.text("LASF_Projection", 16);
  w.put<std::uint16_t>(2112);
  w.put<std::uint16_t>(static_cast<std::uint16_t>(wkt.size() + 1));
  w.text("OGC coordinate system WKT", 32);
  w.text(wkt, wkt.size() + 1);
  // ---- point data records, format 6 (Table 14)
  for (std::size_t i = 0; i < n; ++i) {
    const double v[3] = {p[i].easting_m, p[i].northing_m, p[i].height_m};
    for (int k = 0; k < 3; ++k)
      w.put<std::int32_t>(static_cast<std::int32_t>(std::llround((v[k] - offset[k]) / kScale_m)));
    const float reflectivity = std::clamp(cloud.intensity[i], 0.0f, 255.0f);
    w.put<std::uint16_t>(static_cast<std::uint16_t>(std::lround(static_cast<double>(reflectivity) * 257.0)));
    const auto [number, count] = returns(cloud.return_type[i]);
    w.put<std::uint8_t>(static_cast<std::uint8_t>(number | count << 4));
    w.put<std::uint8_t>(0);  // classification flags, scanner channel, scan direction, edge
    w.put<std::uint8_t>(0);  // classification: created, never classified
    w.put<std::uint8_t>(static_cast<std::uint8_t>(cloud.ring[i]));  // user data: the laser
    w.put<std::int16_t>(0);                                         // scan angle
    w.put<std::uint16_t>(0);                                        // point source id
    w.put<double>(start_s + static_cast<double>(cloud.time_s[i]));
  }
  return out;
}

}  // namespace trajroi::cloud_io
