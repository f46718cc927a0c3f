// Procedural meshes: test and benchmark bodies with known geometry, and the shipped scenes'
// simple parts (sheet, ball). Everything is closed and outward-oriented unless named a sheet.
#pragma once

#include "hapsim/geometry/triangle_mesh.h"

#include <cstddef>

namespace hapsim {

/// Latitude-longitude sphere: `segments` around, `rings` from pole to pole;
/// 2·segments·(rings−1) triangles. Closed, outward-oriented.
TriangleMesh make_uv_sphere(double radius_m, int segments, int rings);

/// A sphere with smooth bumps, r(θ,φ) = R·(1 + a·sin(kθ)·sin(kφ)), with about
/// `target_triangles` triangles (the benchmark's "bumpy closed sphere"). Closed, outward.
TriangleMesh make_bumpy_sphere(std::size_t target_triangles, double radius_m = 0.05,
                               double bump_amplitude = 0.08, int bump_frequency = 7);

/// Axis-aligned box centred at the origin with half extents `half_m`; 12 triangles.
TriangleMesh make_box(const Vec3& half_m);

/// An open square sheet in the z = 0 plane, centred at the origin, with n×n grid nodes over
/// `size_m`×`size_m` (n ≥ 2); 2·(n−1)² triangles, normals +z.
TriangleMesh make_sheet(int nodes_per_side, double size_m);

}  // namespace hapsim
