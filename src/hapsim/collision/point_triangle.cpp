#include "hapsim/collision/point_triangle.h"

#include <algorithm>

namespace hapsim {

// haptic path: no allocation, branches only.
TriangleClosest closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                          const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    return {a, ap.squaredNorm(), TriangleFeature::kVertexA};
  }
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    return {b, bp.squaredNorm(), TriangleFeature::kVertexB};
  }
  const double vc = d1 * d4 - d3 * d2;
  // d1 - d3 = |ab|²: a zero-length edge must not divide 0/0 (NaN); other regions cover it.
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) {
    const double v = d1 / (d1 - d3);
    const Vec3 q = a + v * ab;
    return {q, (p - q).squaredNorm(), TriangleFeature::kEdgeAB};
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    return {c, cp.squaredNorm(), TriangleFeature::kVertexC};
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) {  // d2 - d6 = |ac|²
    const double w = d2 / (d2 - d6);
    const Vec3 q = a + w * ac;
    return {q, (p - q).squaredNorm(), TriangleFeature::kEdgeCA};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    const Vec3 q = b + w * (c - b);
    return {q, (p - q).squaredNorm(), TriangleFeature::kEdgeBC};
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) {
    // Degenerate (zero-area) triangle that slipped past the region tests: take the best edge.
    TriangleClosest best{a, ap.squaredNorm(), TriangleFeature::kVertexA};
    const Vec3* ends[3][2] = {{&a, &b}, {&b, &c}, {&c, &a}};
    const TriangleFeature feats[3] = {TriangleFeature::kEdgeAB, TriangleFeature::kEdgeBC,
                                      TriangleFeature::kEdgeCA};
    for (int e = 0; e < 3; ++e) {
      const Vec3 d = *ends[e][1] - *ends[e][0];
      const double len2 = d.squaredNorm();
      const double t = len2 > 0.0 ? std::clamp((p - *ends[e][0]).dot(d) / len2, 0.0, 1.0) : 0.0;
      const Vec3 q = *ends[e][0] + t * d;
      const double dist2 = (p - q).squaredNorm();
      if (dist2 < best.distance_sq) {
        best = {q, dist2, feats[e]};
      }
    }
    return best;
  }
  const double denom = 1.0 / sum;
  const double v = vb * denom;
  const double w = vc * denom;
  const Vec3 q = a + ab * v + ac * w;
  return {q, (p - q).squaredNorm(), TriangleFeature::kFace};
}

}  // namespace hapsim
