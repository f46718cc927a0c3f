#include "hapsim/geometry/csg.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace hapsim {
namespace csg_detail {

enum class Kind : std::uint8_t {
  kBlock,
  kSphere,
  kCylinder,
  kFrustum,
  kTorus,
  kUnion,
  kIntersection,
  kDifference,
  kTransform,
};

// Immutable once built; shared between solids.
struct Node {
  Kind kind = Kind::kSphere;
  // Block: half extents. Sphere: (r). Cylinder: (r, half height). Frustum: (r_bottom, r_top,
  // half height). Torus: (R, r).
  Vec3 params = Vec3::Zero();
  // Frustum only: outward unit normal of the slanted side in the (ρ, z) half plane.
  Eigen::Vector2d side_normal = Eigen::Vector2d::Zero();
  Iso3 X_parent_child = Iso3::Identity();
  Iso3 X_child_parent = Iso3::Identity();
  std::shared_ptr<const Node> a;
  std::shared_ptr<const Node> b;
  Box3 bounds;
  std::size_t node_count = 1;
};

namespace {

using Vec2 = Eigen::Vector2d;

// A 2D signed distance in the meridian half plane (ρ ≥ 0, z) of a solid of revolution.
struct Sdf2 {
  double d;
  Vec2 g;  // unit gradient (ρ, z)
};

// Lifts a meridian-plane sample back to 3D: ρ direction is radial in xy.
SdfSample lift(const Sdf2& s, const Vec3& p) {
  const double rho = std::hypot(p.x(), p.y());
  // On the axis the radial direction is undefined; any choice is a valid (sub)gradient.
  const Vec3 radial = rho > 0.0 ? Vec3(p.x() / rho, p.y() / rho, 0.0) : Vec3::UnitX();
  return {s.d, s.g.x() * radial + s.g.y() * Vec3::UnitZ(), true};
}

// Exact 2D box (half extents h) distance, used by block (3D version below) and cylinder.
Sdf2 box2(const Vec2& q_abs, const Vec2& sign, const Vec2& half) {
  const Vec2 q = q_abs - half;
  if (q.x() > 0.0 || q.y() > 0.0) {
    const Vec2 w = q.cwiseMax(0.0);
    const double n = w.norm();
    return {n, w.cwiseProduct(sign) / n};
  }
  // Inside: the nearest face is the one with the largest (least negative) q.
  if (q.x() >= q.y()) {
    return {q.x(), Vec2(sign.x(), 0.0)};
  }
  return {q.y(), Vec2(0.0, sign.y())};
}

double sign_of(double v) {
  return v < 0.0 ? -1.0 : 1.0;
}

SdfSample eval_block(const Node& n, const Vec3& p) {
  const Vec3 s(sign_of(p.x()), sign_of(p.y()), sign_of(p.z()));
  const Vec3 q = p.cwiseAbs() - n.params;
  if ((q.array() > 0.0).any()) {
    // Outside: distance to the nearest face, edge or corner (the positive components).
    const Vec3 w = q.cwiseMax(0.0);
    const double d = w.norm();
    return {d, w.cwiseProduct(s) / d, true};
  }
  Eigen::Index k = 0;
  const double d = q.maxCoeff(&k);
  Vec3 g = Vec3::Zero();
  g[k] = s[k];
  return {d, g, true};
}

SdfSample eval_sphere(const Node& n, const Vec3& p) {
  const double r = p.norm();
  // At the centre every direction is a valid gradient; pick +z.
  return {r - n.params.x(), r > 0.0 ? Vec3(p / r) : Vec3(Vec3::UnitZ()), true};
}

SdfSample eval_cylinder(const Node& n, const Vec3& p) {
  const Vec2 q(std::hypot(p.x(), p.y()), std::abs(p.z()));
  return lift(box2(q, Vec2(1.0, sign_of(p.z())), n.params.head<2>()), p);
}

// Distance from q to segment [a, b] and the closest point.
double segment_distance(const Vec2& q, const Vec2& a, const Vec2& b, Vec2* closest) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  *closest = a + t * ab;
  return (q - *closest).norm();
}

// Frustum: the meridian section is a symmetric trapezoid; for ρ ≥ 0 the nearest boundary point
// lies on its right half (bottom half edge, slanted side, top half edge), and inside the
// distance is the largest of the three supporting-line distances (convexity). The mirrored left
// side is never nearer for ρ ≥ 0, so it is left out.
SdfSample eval_frustum(const Node& n, const Vec3& p) {
  const double r0 = n.params.x();
  const double r1 = n.params.y();
  const double h = n.params.z();
  const Vec2 q(std::hypot(p.x(), p.y()), p.z());
  const Vec2 b0(0.0, -h);
  const Vec2 c0(r0, -h);
  const Vec2 c1(r1, h);
  const Vec2 t0(0.0, h);
  const double side = n.side_normal.dot(q - c0);
  const bool inside = q.y() > -h && q.y() < h && side < 0.0;
  if (!inside) {
    Vec2 best_c;
    Vec2 c;
    double best = segment_distance(q, c0, c1, &best_c);
    double d = segment_distance(q, b0, c0, &c);
    if (d < best) {
      best = d;
      best_c = c;
    }
    d = segment_distance(q, c1, t0, &c);
    if (d < best) {
      best = d;
      best_c = c;
    }
    if (best > 0.0) {
      return lift({best, (q - best_c) / best}, p);
    }
    // Exactly on the boundary: use the supporting line normal of the side nearest by lines.
  }
  Sdf2 s{side, n.side_normal};
  // A cap of zero radius (cone apex) is not a face; its line would never win anyway.
  if (r0 > 0.0 && -h - q.y() > s.d) {
    s = {-h - q.y(), Vec2(0.0, -1.0)};
  }
  if (r1 > 0.0 && q.y() - h > s.d) {
    s = {q.y() - h, Vec2(0.0, 1.0)};
  }
  return lift(s, p);
}

SdfSample eval_torus(const Node& n, const Vec3& p) {
  const Vec2 q(std::hypot(p.x(), p.y()) - n.params.x(), p.z());
  const double len = q.norm();
  // On the tube's centre circle every direction in the meridian plane is valid; pick radial.
  const Vec2 g = len > 0.0 ? Vec2(q / len) : Vec2(1.0, 0.0);
  return lift({len - n.params.y(), g}, p);
}

SdfSample eval_node(const Node& n, const Vec3& p) {
  switch (n.kind) {
    case Kind::kBlock:
      return eval_block(n, p);
    case Kind::kSphere:
      return eval_sphere(n, p);
    case Kind::kCylinder:
      return eval_cylinder(n, p);
    case Kind::kFrustum:
      return eval_frustum(n, p);
    case Kind::kTorus:
      return eval_torus(n, p);
    case Kind::kUnion: {
      const SdfSample sa = eval_node(*n.a, p);
      const SdfSample sb = eval_node(*n.b, p);
      SdfSample s = sa.distance_m <= sb.distance_m ? sa : sb;
      // min of exact distances is exact outside the union only.
      s.exact = sa.exact && sb.exact && s.distance_m >= 0.0;
      return s;
    }
    case Kind::kIntersection: {
      const SdfSample sa = eval_node(*n.a, p);
      const SdfSample sb = eval_node(*n.b, p);
      SdfSample s = sa.distance_m >= sb.distance_m ? sa : sb;
      // max of exact distances is exact inside the intersection only.
      s.exact = sa.exact && sb.exact && s.distance_m <= 0.0;
      return s;
    }
    case Kind::kDifference: {
      const SdfSample sa = eval_node(*n.a, p);
      const SdfSample sb = eval_node(*n.b, p);
      SdfSample s = sa.distance_m >= -sb.distance_m ? sa : SdfSample{-sb.distance_m, -sb.gradient};
      s.exact = sa.exact && sb.exact && s.distance_m <= 0.0;
      return s;
    }
    case Kind::kTransform: {
      SdfSample s = eval_node(*n.a, n.X_child_parent * p);
      s.gradient = n.X_parent_child.linear() * s.gradient;
      return s;
    }
  }
  return {};
}

void require_positive(double v, const char* what) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    throw Error("CsgSolid",
                std::string(what) + " must be finite and > 0, got " + std::to_string(v));
  }
}

Box3 transform_box(const Box3& box, const Iso3& X) {
  Box3 out;
  if (box.isEmpty()) {
    return out;
  }
  for (int c = 0; c < 8; ++c) {
    out.extend(X * box.corner(static_cast<Box3::CornerType>(c)));
  }
  return out;
}

std::shared_ptr<Node> make_primitive(Kind kind, const Vec3& params, const Vec3& half_bounds) {
  auto n = std::make_shared<Node>();
  n->kind = kind;
  n->params = params;
  n->bounds = Box3(-half_bounds, half_bounds);
  return n;
}

std::shared_ptr<const Node> combine(Kind kind, std::shared_ptr<const Node> a,
                                    std::shared_ptr<const Node> b) {
  auto n = std::make_shared<Node>();
  n->kind = kind;
  switch (kind) {
    case Kind::kUnion:
      n->bounds = a->bounds.merged(b->bounds);
      break;
    case Kind::kIntersection:
      // An empty intersection box stays empty; the polygoniser then reports an empty solid.
      n->bounds = a->bounds.intersection(b->bounds);
      break;
    default:
      n->bounds = a->bounds;
      break;
  }
  n->node_count = 1 + a->node_count + b->node_count;
  n->a = std::move(a);
  n->b = std::move(b);
  return n;
}

}  // namespace
}  // namespace csg_detail

using csg_detail::Kind;
using csg_detail::Node;

CsgSolid::CsgSolid() = default;
CsgSolid::CsgSolid(std::shared_ptr<const Node> node) : node_(std::move(node)) {}

CsgSolid CsgSolid::block(const Vec3& half_extents_m) {
  for (int i = 0; i < 3; ++i) {
    csg_detail::require_positive(half_extents_m[i], "block half extent");
  }
  return CsgSolid(csg_detail::make_primitive(Kind::kBlock, half_extents_m, half_extents_m));
}

CsgSolid CsgSolid::sphere(double radius_m) {
  csg_detail::require_positive(radius_m, "sphere radius");
  return CsgSolid(
      csg_detail::make_primitive(Kind::kSphere, Vec3(radius_m, 0, 0), Vec3::Constant(radius_m)));
}

CsgSolid CsgSolid::cylinder(double radius_m, double half_height_m) {
  csg_detail::require_positive(radius_m, "cylinder radius");
  csg_detail::require_positive(half_height_m, "cylinder half height");
  return CsgSolid(csg_detail::make_primitive(Kind::kCylinder, Vec3(radius_m, half_height_m, 0),
                                             Vec3(radius_m, radius_m, half_height_m)));
}

CsgSolid CsgSolid::frustum(double bottom_radius_m, double top_radius_m, double half_height_m) {
  const auto non_negative = [](double v, const char* what) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      throw Error("CsgSolid",
                  std::string(what) + " must be finite and >= 0, got " + std::to_string(v));
    }
  };
  non_negative(bottom_radius_m, "frustum bottom radius");
  non_negative(top_radius_m, "frustum top radius");
  csg_detail::require_positive(std::max(bottom_radius_m, top_radius_m), "frustum larger radius");
  csg_detail::require_positive(half_height_m, "frustum half height");
  const double r = std::max(bottom_radius_m, top_radius_m);
  auto n =
      csg_detail::make_primitive(Kind::kFrustum, Vec3(bottom_radius_m, top_radius_m, half_height_m),
                                 Vec3(r, r, half_height_m));
  // Side direction (r1 − r0, 2h) turned clockwise points away from the axis.
  n->side_normal =
      Eigen::Vector2d(2.0 * half_height_m, bottom_radius_m - top_radius_m).normalized();
  return CsgSolid(std::move(n));
}

CsgSolid CsgSolid::cone(double base_radius_m, double height_m) {
  csg_detail::require_positive(base_radius_m, "cone base radius");
  csg_detail::require_positive(height_m, "cone height");
  return frustum(base_radius_m, 0.0, 0.5 * height_m)
      .transformed(Iso3(Eigen::Translation3d(0.0, 0.0, 0.5 * height_m)));
}

CsgSolid CsgSolid::torus(double major_radius_m, double minor_radius_m) {
  csg_detail::require_positive(major_radius_m, "torus major radius");
  csg_detail::require_positive(minor_radius_m, "torus minor radius");
  if (minor_radius_m > major_radius_m) {
    // A spindle torus overlaps itself across the axis; |(ρ−R, z)| − r is then not exact.
    throw Error("CsgSolid", "torus minor radius (" + std::to_string(minor_radius_m) +
                                ") must not exceed the major radius (" +
                                std::to_string(major_radius_m) + ")");
  }
  const double rr = major_radius_m + minor_radius_m;
  return CsgSolid(csg_detail::make_primitive(Kind::kTorus, Vec3(major_radius_m, minor_radius_m, 0),
                                             Vec3(rr, rr, minor_radius_m)));
}

CsgSolid CsgSolid::transformed(const Iso3& X_parent_self) const {
  const Mat3 R = X_parent_self.linear();
  const Vec3 t = X_parent_self.translation();
  if (!R.allFinite() || !t.allFinite() ||
      (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9 ||
      R.determinant() < 0.0) {
    throw Error("CsgSolid::transformed",
                "transform must be rigid (orthonormal rotation with det +1, finite translation)");
  }
  if (!node_) {
    return *this;
  }
  Iso3 X = X_parent_self;
  std::shared_ptr<const Node> child = node_;
  if (node_->kind == Kind::kTransform) {
    X = X_parent_self * node_->X_parent_child;
    child = node_->a;
  }
  auto n = std::make_shared<Node>();
  n->kind = Kind::kTransform;
  n->X_parent_child = X;
  n->X_child_parent = X.inverse(Eigen::Isometry);
  n->bounds = csg_detail::transform_box(child->bounds, X);
  n->node_count = 1 + child->node_count;
  n->a = std::move(child);
  return CsgSolid(std::move(n));
}

SdfSample CsgSolid::evaluate(const Vec3& p_S) const {
  if (!node_) {
    return {kInf, Vec3::Zero(), true};
  }
  return csg_detail::eval_node(*node_, p_S);
}

double CsgSolid::distance(const Vec3& p_S) const {
  return evaluate(p_S).distance_m;
}

std::size_t CsgSolid::memory_bytes() const {
  return node_count() * sizeof(Node);
}

Box3 CsgSolid::bounds() const {
  return node_ ? node_->bounds : Box3();
}

std::size_t CsgSolid::node_count() const {
  return node_ ? node_->node_count : 0;
}

CsgSolid csg_union(const CsgSolid& a, const CsgSolid& b) {
  if (!a.node_) {
    return b;
  }
  if (!b.node_) {
    return a;
  }
  return CsgSolid(csg_detail::combine(Kind::kUnion, a.node_, b.node_));
}

CsgSolid csg_intersection(const CsgSolid& a, const CsgSolid& b) {
  if (!a.node_ || !b.node_) {
    return CsgSolid();
  }
  return CsgSolid(csg_detail::combine(Kind::kIntersection, a.node_, b.node_));
}

CsgSolid csg_difference(const CsgSolid& a, const CsgSolid& b) {
  if (!a.node_ || !b.node_) {
    return a;
  }
  return CsgSolid(csg_detail::combine(Kind::kDifference, a.node_, b.node_));
}

}  // namespace hapsim
