// Volume, centre of mass and inertia of a closed, outward-oriented triangle mesh of uniform
// density: the surface integrals of the divergence theorem summed over the triangles (Eberly,
// "Polyhedral Mass Properties (Revisited)"). What a dynamic body's mass properties come from when
// a scene gives only its mass or density.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/geometry/triangle_mesh.h"

namespace hapsim {

struct MassProperties {
  double volume_m3 = 0.0;
  /// Centre of mass in the mesh frame, metres.
  Vec3 com = Vec3::Zero();
  /// Inertia about the centre of mass (mesh axes) for a density of 1 kg/m³: multiply by the
  /// density, or by mass / volume.
  Mat3 inertia_per_density = Mat3::Zero();
};

/// Throws hapsim::Error when the enclosed volume is not positive (an open or inward-facing mesh).
[[nodiscard]] MassProperties mass_properties(const TriangleMesh& mesh);

}  // namespace hapsim
