// Minimal enclosing spheres: of points (a leaf's triangle corners, the tightness reference) and of
// spheres (a parent around its children, so the tree's "parent bounds child" rule holds after
// refit too). Welzl's randomized incremental algorithm in its iterative four-loop form: expected
// O(n), recursion-free, exact up to rounding. Every result is finally widened to its farthest
// input, so nothing is ever outside the returned sphere, whatever the rounding.
#pragma once

#include "hapsim/collision/sphere_tree.h"  // Sphere
#include "hapsim/core/types.h"

#include <cstdint>
#include <optional>
#include <span>

namespace hapsim {

/// Minimal sphere enclosing `points`. Reorders `points` (shuffled with a fixed seed when
/// `shuffle`, which makes the expected time linear for large sets). No allocation.
Sphere minimal_sphere_inplace(std::span<Vec3> points, bool shuffle = true);

/// Minimal sphere of one triangle's corners, in closed form (circumcircle if acute, else the
/// longest edge's diameter sphere). No allocation.
Sphere triangle_sphere(const Vec3& a, const Vec3& b, const Vec3& c);

/// Minimal sphere enclosing `points` (copies them; allocates).
Sphere minimal_sphere(std::span<const Vec3> points);

/// Smallest sphere enclosing the spheres `spheres` (reordered). Exact for points and in generic
/// configurations; Welzl's scheme is not guaranteed optimal for balls (Fischer & Gärtner 2003),
/// so in rare degenerate cases it may be slightly larger than minimal — never too small.
/// No allocation.
Sphere enclosing_sphere_inplace(std::span<Sphere> spheres);

/// As above on a copy. Allocates only beyond 64 spheres.
Sphere enclosing_sphere(std::span<const Sphere> spheres);

/// The smallest sphere internally tangent to all of `support` (1–4 spheres, or points with
/// radius 0), its centre in their centres' affine hull: the candidate a support set defines.
/// nullopt when degenerate (e.g. three collinear points).
std::optional<Sphere> sphere_through(std::span<const Sphere> support);

/// Ritter's approximate bounding sphere (1990): a quick upper bound used to check the exact one.
Sphere ritter_sphere(std::span<const Vec3> points);

/// Smallest radius R such that `s` encloses everything, keeping its centre.
double enclosing_radius(const Vec3& center, std::span<const Vec3> points);
double enclosing_radius(const Vec3& center, std::span<const Sphere> spheres);

}  // namespace hapsim
