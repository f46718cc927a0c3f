// Constructive solid geometry (seed 000 §3.1): primitives (block, sphere, cylinder, cone/frustum,
// torus) combined by union, intersection and difference, placed by rigid transforms, with a
// signed-distance evaluation for contact queries and bounds for the polygoniser.
//
// Signed distance convention: negative inside, positive outside, zero on the surface; the
// gradient is unit length and points outward.
//
// Exactness (what `SdfSample::exact` reports):
//  * every primitive gives the exact Euclidean signed distance everywhere;
//  * union (min) is exact outside the union, intersection (max) is exact inside the
//    intersection, difference a − b = max(a, −b) is exact inside the result — each provided the
//    children are exact at the point; elsewhere the value is a bound;
//  * everywhere, for every tree: the sign is exact and |distance| ≤ the true distance to the
//    surface (the field is 1-Lipschitz), so stepping |distance| never crosses the surface.
// Gradients are those of the active child (for a difference where the subtracted child is
// active, its negated gradient); at ties the left child wins. On a medial axis (equidistant
// from two surface parts) any one of the valid directions is returned.
#pragma once

#include "hapsim/core/types.h"

#include <cstddef>
#include <memory>

namespace hapsim {

/// One evaluation of a signed distance field.
struct SdfSample {
  /// Signed distance, metres: negative inside, positive outside (+inf for the empty solid).
  double distance_m = kInf;
  /// Unit outward gradient of the distance (zero for the empty solid).
  Vec3 gradient = Vec3::Zero();
  /// True when `distance_m` is the exact Euclidean signed distance (see the file comment);
  /// false when it is only a conservative bound (right sign, magnitude ≤ true distance).
  bool exact = true;
};

namespace csg_detail {
struct Node;
}  // namespace csg_detail

/// An immutable CSG tree. A value type: copies share nodes (cheap), evaluation is thread-safe,
/// allocates nothing and takes no lock (haptic path). The default-constructed solid is empty.
/// Every factory throws hapsim::Error for non-positive or non-finite dimensions.
class CsgSolid {
 public:
  /// The empty solid (distance +inf everywhere); the identity of union.
  CsgSolid();

  /// Axis-aligned box centred at the origin, half extents `half_extents_m` (> 0 each).
  static CsgSolid block(const Vec3& half_extents_m);
  /// Sphere centred at the origin.
  static CsgSolid sphere(double radius_m);
  /// Capped cylinder along z, centred at the origin, z ∈ [−half_height, +half_height].
  static CsgSolid cylinder(double radius_m, double half_height_m);
  /// Capped cone along z: base disc of `base_radius_m` at z = 0, apex at z = `height_m`.
  static CsgSolid cone(double base_radius_m, double height_m);
  /// Capped cone frustum along z, centred at the origin: radius `bottom_radius_m` at
  /// z = −half_height, `top_radius_m` at z = +half_height (each ≥ 0, not both 0).
  static CsgSolid frustum(double bottom_radius_m, double top_radius_m, double half_height_m);
  /// Ring torus in the xy plane centred at the origin: tube centre circle of radius
  /// `major_radius_m`, tube radius `minor_radius_m` (0 < minor ≤ major).
  static CsgSolid torus(double major_radius_m, double minor_radius_m);

  /// This solid placed in a parent frame P: the returned solid's points are p_P = X_PS · p_S.
  /// `X_parent_self` must be rigid (orthonormal rotation, det +1, finite), else hapsim::Error.
  /// Nested transforms are composed into one node.
  [[nodiscard]] CsgSolid transformed(const Iso3& X_parent_self) const;

  /// Signed distance and gradient at `p_S` (a point in this solid's frame). Haptic path.
  [[nodiscard]] SdfSample evaluate(const Vec3& p_S) const;
  /// Signed distance only (same value as evaluate().distance_m). Haptic path.
  [[nodiscard]] double distance(const Vec3& p_S) const;
  /// True when `p_S` is strictly inside (distance < 0).
  [[nodiscard]] bool contains(const Vec3& p_S) const { return distance(p_S) < 0.0; }

  /// A conservative axis-aligned box containing the solid (empty box for the empty solid).
  /// Not necessarily tight: rotated children and differences enlarge it.
  [[nodiscard]] Box3 bounds() const;
  /// True for the structurally empty solid (no primitive). A tree such as
  /// sphere(1) − sphere(2) is not structurally empty though it contains no point.
  [[nodiscard]] bool is_empty() const { return node_ == nullptr; }
  /// Number of nodes in the tree (primitives, booleans and transforms); 0 when empty.
  [[nodiscard]] std::size_t node_count() const;
  /// Bytes of the tree's nodes (shared subtrees counted once per use: an upper bound).
  [[nodiscard]] std::size_t memory_bytes() const;

  friend CsgSolid csg_union(const CsgSolid& a, const CsgSolid& b);
  friend CsgSolid csg_intersection(const CsgSolid& a, const CsgSolid& b);
  friend CsgSolid csg_difference(const CsgSolid& a, const CsgSolid& b);

 private:
  explicit CsgSolid(std::shared_ptr<const csg_detail::Node> node);
  std::shared_ptr<const csg_detail::Node> node_;
};

/// a ∪ b (distance min(a, b)).
CsgSolid csg_union(const CsgSolid& a, const CsgSolid& b);
/// a ∩ b (distance max(a, b)).
CsgSolid csg_intersection(const CsgSolid& a, const CsgSolid& b);
/// a − b = a ∩ complement(b) (distance max(a, −b)).
CsgSolid csg_difference(const CsgSolid& a, const CsgSolid& b);

inline CsgSolid operator|(const CsgSolid& a, const CsgSolid& b) {
  return csg_union(a, b);
}
inline CsgSolid operator&(const CsgSolid& a, const CsgSolid& b) {
  return csg_intersection(a, b);
}
inline CsgSolid operator-(const CsgSolid& a, const CsgSolid& b) {
  return csg_difference(a, b);
}

}  // namespace hapsim
