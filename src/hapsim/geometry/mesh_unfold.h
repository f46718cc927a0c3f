// Removing folds from a closed triangle mesh by edge flips. An edge-collapse simplifier
// (meshoptimizer) can leave a fin at a sharp edge of the source: two faces sharing an edge that
// turn back on each other. Beside a fin the closest point's pseudo-normal can say "inside" for a
// point well outside (4% of points near the simplified patellar tendon were wrong), which made a
// proxy lose the tendon; fins also cross neighbouring faces, which a mesher refuses.
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>

namespace hapsim {

/// Removes folded edges (see MeshReport::folded_edges) of a closed, consistently oriented mesh:
/// flips each to the other diagonal of its two triangles wherever that leaves fewer folds among
/// the five edges involved and no degenerate triangle; a fold no flip removes is collapsed onto
/// one of its ends when that keeps the mesh closed with the same Euler characteristic and
/// lowers the fold count. Surviving vertices keep their positions. Returns the flips and
/// collapses made.
std::size_t unfold_edges(TriangleMesh& mesh);

}  // namespace hapsim
