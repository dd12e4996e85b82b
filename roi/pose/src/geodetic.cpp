#include "trajroi/pose/geodetic.hpp"

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

namespace trajroi::pose {

namespace {

constexpr double kDegToRad = 0.017453292519943295;

void check_geodetic(const Geodetic& g, const char* what) {
  if (!(std::abs(g.lat_deg) <= 90.0) || !(std::abs(g.lon_deg) <= 180.0) || !std::isfinite(g.height_m)) {
    throw std::invalid_argument(std::string(what) + ": latitude " + std::to_string(g.lat_deg) + ", longitude " +
                                std::to_string(g.lon_deg) + " is not a WGS84 position");
  }
}

// Columns: east, north, up of the local tangent frame at (lat, lon), in ECEF.
Eigen::Matrix3d ecef_from_enu(double lat_deg, double lon_deg) {
  const double sp = std::sin(lat_deg * kDegToRad);
  const double cp = std::cos(lat_deg * kDegToRad);
  const double sl = std::sin(lon_deg * kDegToRad);
  const double cl = std::cos(lon_deg * kDegToRad);
  Eigen::Matrix3d m;
  m << -sl, -sp * cl, cp * cl,  //
      cl, -sp * sl, cp * sl,    //
      0.0, cp, sp;
  return m;
}

Eigen::Matrix3d rot_z(double rad) {
  return Eigen::AngleAxisd(rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

struct GlobalFrame::Impl {
  bool utm = false;
  // LocalCartesian
  GeographicLib::LocalCartesian local;
  Eigen::Matrix3d enu0_from_ecef = Eigen::Matrix3d::Identity();
  // UTM / UPS
  int zone = 0;
  bool northern = true;

  double convergence_deg(const Geodetic& p) const {
    int z = 0;
    bool north = false;
    double x = 0, y = 0, gamma = 0, k = 0;
    GeographicLib::UTMUPS::Forward(p.lat_deg, p.lon_deg, z, north, x, y, gamma, k, zone);
    return gamma;
  }
};

GlobalFrame::GlobalFrame(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GlobalFrame::GlobalFrame(const GlobalFrame& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
GlobalFrame& GlobalFrame::operator=(const GlobalFrame& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
GlobalFrame::GlobalFrame(GlobalFrame&&) noexcept = default;
GlobalFrame& GlobalFrame::operator=(GlobalFrame&&) noexcept = default;
GlobalFrame::~GlobalFrame() = default;

GlobalFrame GlobalFrame::local_cartesian(const Geodetic& origin) {
  check_geodetic(origin, "global frame origin");
  auto impl = std::make_unique<Impl>();
  impl->local.Reset(origin.lat_deg, origin.lon_deg, origin.height_m);
  impl->enu0_from_ecef = ecef_from_enu(origin.lat_deg, origin.lon_deg).transpose();
  return GlobalFrame(std::move(impl));
}

GlobalFrame GlobalFrame::utm(int zone, bool northern) {
  if (zone < GeographicLib::UTMUPS::MINZONE || zone > GeographicLib::UTMUPS::MAXZONE) {
    throw std::invalid_argument("UTM zone " + std::to_string(zone) + " is not 1 … 60 (or 0 for UPS)");
  }
  auto impl = std::make_unique<Impl>();
  impl->utm = true;
  impl->zone = zone;
  impl->northern = northern;
  return GlobalFrame(std::move(impl));
}

bool GlobalFrame::is_utm() const noexcept {
  return impl_->utm;
}

Eigen::Vector3d GlobalFrame::to_global(const Geodetic& p) const {
  check_geodetic(p, "geodetic position");
  if (!impl_->utm) {
    Eigen::Vector3d enu;
    impl_->local.Forward(p.lat_deg, p.lon_deg, p.height_m, enu.x(), enu.y(), enu.z());
    return enu;
  }
  int z = 0;
  bool north = false;
  double x = 0, y = 0, gamma = 0, k = 0;
  try {
    GeographicLib::UTMUPS::Forward(p.lat_deg, p.lon_deg, z, north, x, y, gamma, k, impl_->zone);
  } catch (const GeographicLib::GeographicErr& e) {
    throw std::invalid_argument(std::string("position outside the configured UTM/UPS zone: ") + e.what());
  }
  // Forward uses the hemisphere of the point; keep one continuous northing for the
  // configured hemisphere (a southern point in a northern zone gets a negative northing).
  if (impl_->zone != GeographicLib::UTMUPS::UPS && north != impl_->northern) {
    y += impl_->northern ? -GeographicLib::UTMUPS::UTMShift() : GeographicLib::UTMUPS::UTMShift();
  }
  return {x, y, p.height_m};
}

Geodetic GlobalFrame::to_geodetic(const Eigen::Vector3d& g) const {
  Geodetic out;
  if (!impl_->utm) {
    impl_->local.Reverse(g.x(), g.y(), g.z(), out.lat_deg, out.lon_deg, out.height_m);
    return out;
  }
  double gamma = 0, k = 0;
  GeographicLib::UTMUPS::Reverse(impl_->zone, impl_->northern, g.x(), g.y(), out.lat_deg, out.lon_deg, gamma, k,
                                 /*mgrslimits=*/false);
  out.height_m = g.z();
  return out;
}

Eigen::Matrix3d GlobalFrame::global_from_local_enu(const Geodetic& p) const {
  check_geodetic(p, "geodetic position");
  if (!impl_->utm) return impl_->enu0_from_ecef * ecef_from_enu(p.lat_deg, p.lon_deg);
  return rot_z(impl_->convergence_deg(p) * kDegToRad);
}

double GlobalFrame::global_yaw_from_true_bearing(double bearing_deg, const Geodetic& p) const {
  const double b = bearing_deg * kDegToRad;
  const Eigen::Vector3d dir = global_from_local_enu(p) * Eigen::Vector3d(std::sin(b), std::cos(b), 0.0);
  return std::atan2(dir.y(), dir.x());
}

}  // namespace trajroi::pose
