#include "hapsim/deform/sheet_query.h"

#include <cmath>

namespace hapsim {

namespace {

SurfacePoint to_surface_point(const SheetSphereContact& c, double radius_m) {
  SurfacePoint sp;
  sp.point = c.p_sheet;
  sp.normal = c.normal_sheet;
  sp.signed_distance = radius_m - c.penetration_m;
  sp.triangle = kSdfSurface;
  return sp;
}

}  // namespace

// haptic path
SurfacePoint SheetQuery::closest_point(const Vec3& p, QueryHint* /*hint*/) const {
  // A sphere reaching past the whole square finds the closest point wherever it is.
  const double reach = 2.0 * sheet_->side_m() + std::abs(p.z()) + 1.0;
  const SheetSphereContact c = sheet_->sphere_contact(p, reach, layer_);
  return c.touching ? to_surface_point(c, reach) : SurfacePoint{};
}

// haptic path
bool SheetQuery::contact_within(const Vec3& p, double radius, SurfacePoint* out,
                                QueryHint* /*hint*/) const {
  const SheetSphereContact c = sheet_->sphere_contact(p, radius, layer_);
  if (!c.touching) {
    return false;
  }
  const SurfacePoint sp = to_surface_point(c, radius);
  if (std::abs(sp.signed_distance) > radius) {
    return false;  // deeper below the sheet than the radius
  }
  if (out != nullptr) {
    *out = sp;
  }
  return true;
}

}  // namespace hapsim
