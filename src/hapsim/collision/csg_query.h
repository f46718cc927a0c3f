// Contact with a CSG solid from its signed distance (seed 000 §3.1), not from a mesh: the closest
// point is p − d·∇d, the normal ∇d, the signed distance d, exact up to rounding wherever the
// solid's field is exact (every primitive; outside a union, inside an intersection or a
// difference — see csg.h).
//
// Where the field is only a bound (|d| ≤ true distance, sign exact: e.g. in the hole of a
// difference near its rim, or inside two overlapping parts of a union), the answer is refined
// in two steps, cheapest first:
//  1. certify: the candidate q = p − d·∇d is at distance |d| from p, and no surface point is
//     nearer than |d| (the bound). If q is on the surface, it is therefore a closest point and
//     |d| the exact distance. "On the surface" is checked with exact samples only: the field is
//     sampled a hair (kCsgCertifyStepM) to either side of q along ∇d, and q passes when one of
//     those samples is exact and within two hairs of zero. This answers most bound cases (a
//     hole's wall, a bowl's inner face) exactly, for two more evaluations.
//  2. otherwise (near a rim, where the nearest surface point is on an edge the bound cannot
//     see): the exact closest point on the polygonised mesh, through a MeshBvh built on it. Its
//     error is the polygoniser's (vertices on the surface, edges bevelled by about a cell), the
//     same accuracy as a mesh-only body, and it stays allocation-free and bounded in time.
//     Sphere tracing or projection iterations were not used: they converge to *a* surface point,
//     not the closest one, with no bound on the error at edges.
// The early exit of contact_within needs no refinement: a bound above the radius already proves
// that the surface is farther.
#pragma once

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/proximity_query.h"
#include "hapsim/geometry/csg.h"
#include "hapsim/geometry/triangle_mesh.h"

#include <cstdint>

namespace hapsim {

/// Half-width of the certification probe, metres (see the file comment): a certified answer's
/// distance is exact to within 3 × this.
inline constexpr double kCsgCertifyStepM = 1e-9;

/// How an answer was found, for tests and diagnostics.
enum class CsgAnswer : std::uint8_t {
  kExactField,  ///< the field was exact at the query point
  kCertified,   ///< a bound whose candidate point was proved to be on the surface
  kMesh,        ///< the polygonised mesh's exact query (the bound could not be certified)
};

class CsgQuery final : public ProximityQuery {
 public:
  /// `solid` in the segment's frame (copied: nodes are shared, cheap); `mesh` is its polygonised
  /// surface in the same frame, which must outlive the query (the fallback BVH reads it).
  /// Throws hapsim::Error for an empty solid or an empty mesh.
  CsgQuery(CsgSolid solid, const TriangleMesh& mesh);

  /// haptic path. `triangle` is kSdfSurface for answers from the field; a mesh answer gives the
  /// mesh triangle (and reads/updates `hint` as MeshBvh does; field answers leave it alone).
  [[nodiscard]] SurfacePoint closest_point(const Vec3& p, QueryHint* hint = nullptr) const override;
  /// haptic path.
  bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                      QueryHint* hint = nullptr) const override;
  /// Rigid: nothing to refit (a deformable CSG body deflects its display mesh; contact depths
  /// are measured against the rest solid, as for every body).
  void refit() override {}
  /// The solid's nodes, the fallback BVH (sign data included) and this object.
  [[nodiscard]] std::size_t memory_bytes() const override;
  [[nodiscard]] std::string_view method_name() const override { return "csg"; }

  /// As closest_point, also saying how the answer was found. haptic path.
  [[nodiscard]] SurfacePoint closest_point_explained(const Vec3& p, QueryHint* hint,
                                                     CsgAnswer* how) const;

  [[nodiscard]] const CsgSolid& solid() const { return solid_; }
  [[nodiscard]] const MeshBvh& mesh_query() const { return mesh_bvh_; }

 private:
  // The field's answer at p when exact or certified; false when only the mesh can answer.
  bool field_answer(const Vec3& p, const SdfSample& s, SurfacePoint* out, CsgAnswer* how) const;

  CsgSolid solid_;
  MeshBvh mesh_bvh_;
};

}  // namespace hapsim
