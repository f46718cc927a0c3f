#include "hapsim/collision/csg_query.h"

#include "hapsim/core/error.h"

#include <cmath>

namespace hapsim {
namespace {

const TriangleMesh& checked_mesh(const CsgSolid& solid, const TriangleMesh& mesh) {
  if (solid.is_empty()) {
    throw Error("CsgQuery", "needs a non-empty solid");
  }
  if (mesh.triangles.empty()) {
    throw Error("CsgQuery", "needs the solid's polygonised mesh (got one without triangles)");
  }
  return mesh;
}

}  // namespace

CsgQuery::CsgQuery(CsgSolid solid, const TriangleMesh& mesh)
    : solid_(std::move(solid)), mesh_bvh_(checked_mesh(solid_, mesh)) {}

// haptic path
bool CsgQuery::field_answer(const Vec3& p, const SdfSample& s, SurfacePoint* out,
                            CsgAnswer* how) const {
  const Vec3 q = p - s.distance_m * s.gradient;
  if (!s.exact) {
    // Certify q as a surface point with exact samples a hair inside and outside it (a union is
    // exact outside, an intersection or difference inside, so one side usually is).
    bool on_surface = false;
    for (const double side : {-1.0, 1.0}) {
      const SdfSample t = solid_.evaluate(q + side * kCsgCertifyStepM * s.gradient);
      if (t.exact && std::abs(t.distance_m) <= 2.0 * kCsgCertifyStepM) {
        on_surface = true;
        break;
      }
    }
    if (!on_surface) {
      return false;
    }
  }
  out->point = q;
  out->normal = s.gradient;
  out->signed_distance = s.distance_m;
  out->triangle = kSdfSurface;
  if (how != nullptr) {
    *how = s.exact ? CsgAnswer::kExactField : CsgAnswer::kCertified;
  }
  return true;
}

// haptic path
SurfacePoint CsgQuery::closest_point_explained(const Vec3& p, QueryHint* hint,
                                               CsgAnswer* how) const {
  SurfacePoint sp;
  if (field_answer(p, solid_.evaluate(p), &sp, how)) {
    return sp;
  }
  if (how != nullptr) {
    *how = CsgAnswer::kMesh;
  }
  return mesh_bvh_.closest_point(p, hint);
}

// haptic path
SurfacePoint CsgQuery::closest_point(const Vec3& p, QueryHint* hint) const {
  return closest_point_explained(p, hint, nullptr);
}

// haptic path
bool CsgQuery::contact_within(const Vec3& p, double radius, SurfacePoint* out,
                              QueryHint* hint) const {
  const SdfSample s = solid_.evaluate(p);
  // Exact or a bound, |d| never exceeds the true distance: beyond the radius means clear (or
  // deeper inside than the radius). Written so that NaN is "no contact".
  if (!(std::abs(s.distance_m) <= radius)) {
    return false;
  }
  if (field_answer(p, s, out, nullptr)) {
    return true;
  }
  return mesh_bvh_.contact_within(p, radius, out, hint);
}

std::size_t CsgQuery::memory_bytes() const {
  return sizeof(*this) + solid_.memory_bytes() + mesh_bvh_.memory_bytes();
}

}  // namespace hapsim
