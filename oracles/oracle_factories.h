// Internal: one factory per reference library, each defined in its own translation unit so the
// library's heavy headers compile once. Declared only when the library was found.
#pragma once

#include "oracles/closest_point_oracle.h"

namespace hapsim::oracle {

#ifdef HAPSIM_HAVE_CGAL
/// CGAL AABB_tree closest_point_and_primitive; `use_hint` passes the previous answer as hint.
std::unique_ptr<ClosestPointOracle> make_cgal_oracle(const TriangleMesh& mesh, bool use_hint);
#endif
#ifdef HAPSIM_HAVE_FCL
/// FCL distance between a zero-radius sphere and a BVHModel<OBBRSS>.
std::unique_ptr<ClosestPointOracle> make_fcl_oracle(const TriangleMesh& mesh);
#endif
#ifdef HAPSIM_HAVE_EMBREE
/// Embree rtcPointQuery with a closest-point-on-triangle callback.
std::unique_ptr<ClosestPointOracle> make_embree_oracle(const TriangleMesh& mesh);
#endif

}  // namespace hapsim::oracle
