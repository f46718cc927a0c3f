// CGAL AABB_tree reference: closest_point_and_primitive over the mesh's triangles, optionally
// seeded with the previous answer (the "cgal-hint" row), which is how CGAL exploits coherence.
#include "hapsim/core/stopwatch.h"
#include "oracles/oracle_factories.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <vector>

namespace hapsim::oracle {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIt = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIt>;
using Traits = CGAL::AABB_traits<Kernel, Primitive>;
using Tree = CGAL::AABB_tree<Traits>;

Point to_cgal(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

class CgalOracle final : public ClosestPointOracle {
 public:
  CgalOracle(const TriangleMesh& mesh, bool use_hint) : use_hint_(use_hint) {
    const Stopwatch watch;
    triangles_.reserve(mesh.triangles.size());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto [a, b, c] = mesh.corners(t);
      triangles_.emplace_back(to_cgal(a), to_cgal(b), to_cgal(c));
    }
    tree_.insert(triangles_.cbegin(), triangles_.cend());
    tree_.build();
    // Without a hint CGAL seeds each query from a kd-tree over sample points; with one, the
    // previous answer does that job and the kd-tree is not needed.
    if (!use_hint_ && !triangles_.empty()) {
      tree_.accelerate_distance_queries();
    }
    build_ms_ = watch.elapsed_ms();
  }

  [[nodiscard]] std::string name() const override { return use_hint_ ? "cgal-hint" : "cgal"; }

  [[nodiscard]] OracleAnswer closest(const Vec3& p) override {
    OracleAnswer answer;
    if (triangles_.empty()) {
      answer.distance = kInf;
      return answer;
    }
    const Point q = to_cgal(p);
    const Tree::Point_and_primitive_id pp = (use_hint_ && has_last_)
                                                ? tree_.closest_point_and_primitive(q, last_)
                                                : tree_.closest_point_and_primitive(q);
    last_ = pp;
    has_last_ = true;
    answer.point = Vec3(pp.first.x(), pp.first.y(), pp.first.z());
    answer.distance = (answer.point - p).norm();
    answer.triangle = static_cast<std::uint32_t>(pp.second - triangles_.cbegin());
    return answer;
  }

  [[nodiscard]] double build_ms() const override { return build_ms_; }

  [[nodiscard]] std::size_t memory_bytes() const override {
    // Estimate: the triangle copy, one primitive (iterator) per triangle, n-1 nodes (a box and
    // two child pointers each), and when built the kd-tree of one point and id per triangle
    // (CGAL's kd-tree nodes add roughly as much again).
    const std::size_t n = triangles_.size();
    const std::size_t node_bytes = sizeof(CGAL::Bbox_3) + 2 * sizeof(void*);
    std::size_t bytes =
        n * sizeof(Triangle) + n * sizeof(Primitive) + (n > 0 ? n - 1 : 0) * node_bytes;
    if (!use_hint_) {
      bytes += 2 * n * (sizeof(Point) + sizeof(TriangleIt));
    }
    return bytes;
  }

 private:
  bool use_hint_;
  std::vector<Triangle> triangles_;
  Tree tree_;
  Tree::Point_and_primitive_id last_;
  bool has_last_ = false;
  double build_ms_ = 0.0;
};

}  // namespace

std::unique_ptr<ClosestPointOracle> make_cgal_oracle(const TriangleMesh& mesh, bool use_hint) {
  return std::make_unique<CgalOracle>(mesh, use_hint);
}

}  // namespace hapsim::oracle
