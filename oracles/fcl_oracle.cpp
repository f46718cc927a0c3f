// FCL reference: distance between a zero-radius sphere at the query point and a
// BVHModel<OBBRSS> of the mesh (FCL 0.7, libccd solver; sphere-vs-triangle is FCL's exact
// closed-form sphereTriangleDistance, so answers are exact in double).
//
// Frames: fcl::distance reports nearest_points[0] on the first object (the mesh) in the world
// frame, and for the sphere FCL 0.7 converts its point back into the sphere's local frame
// (sphereTriangleDistance ends with `tf.inverse() * p1`). The mesh is placed at identity, so
// nearest_points[0] is already in the mesh frame; we never read nearest_points[1].
#include "oracles/oracle_factories.h"

#include "hapsim/core/stopwatch.h"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/distance.h>
#include <fcl/narrowphase/distance_request.h>
#include <fcl/narrowphase/distance_result.h>

#include <memory>
#include <stdexcept>
#include <vector>

namespace hapsim::oracle {
namespace {

class FclOracle final : public ClosestPointOracle {
 public:
  explicit FclOracle(const TriangleMesh& mesh)
      : model_(std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>()),
        // Radius 0: the sphere is the query point itself, so distance = point-to-mesh distance.
        point_(std::make_shared<fcl::Sphered>(0.0)) {
    const Stopwatch watch;
    std::vector<fcl::Vector3d> vertices(mesh.vertices.begin(), mesh.vertices.end());
    std::vector<fcl::Triangle> triangles;
    triangles.reserve(mesh.triangles.size());
    for (const TriangleIndices& t : mesh.triangles) {
      triangles.emplace_back(t[0], t[1], t[2]);
    }
    if (model_->beginModel(static_cast<int>(triangles.size()), static_cast<int>(vertices.size())) !=
            fcl::BVH_OK ||
        model_->addSubModel(vertices, triangles) != fcl::BVH_OK ||
        model_->endModel() != fcl::BVH_OK) {
      throw std::runtime_error("fcl: BVHModel<OBBRSS> construction failed");
    }
    model_->computeLocalAABB();
    build_ms_ = watch.elapsed_ms();
    request_.enable_nearest_points = true;
    request_.enable_signed_distance = false;
    request_.rel_err = 0.0;
    request_.abs_err = 0.0;
  }

  [[nodiscard]] std::string name() const override { return "fcl"; }

  [[nodiscard]] OracleAnswer closest(const Vec3& p) override {
    fcl::DistanceResultd result;
    fcl::Transform3d X_world_point = fcl::Transform3d::Identity();
    X_world_point.translation() = p;
    const double d = fcl::distance(model_.get(), fcl::Transform3d::Identity(), point_.get(),
                                   X_world_point, request_, result);
    OracleAnswer answer;
    answer.distance = d;
    answer.point = result.nearest_points[0];
    answer.triangle = result.b1 >= 0 ? static_cast<std::uint32_t>(result.b1) : kNoTriangle;
    return answer;
  }

  [[nodiscard]] double build_ms() const override { return build_ms_; }

  [[nodiscard]] std::size_t memory_bytes() const override {
    // Its BV nodes, its own copy of the vertices (double) and triangles, and the primitive
    // index permutation. (BVHModel::memUsage() computes this but returns BVH_OK, i.e. 0.)
    const auto bvs = static_cast<std::size_t>(model_->getNumBVs());
    const auto tris = static_cast<std::size_t>(model_->num_tris);
    const auto verts = static_cast<std::size_t>(model_->num_vertices);
    return bvs * sizeof(fcl::BVNode<fcl::OBBRSSd>) + tris * sizeof(fcl::Triangle) +
           verts * sizeof(fcl::Vector3d) + tris * sizeof(unsigned int) + sizeof(*model_);
  }

 private:
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> model_;
  std::shared_ptr<fcl::Sphered> point_;
  fcl::DistanceRequestd request_;
  double build_ms_ = 0.0;
};

}  // namespace

std::unique_ptr<ClosestPointOracle> make_fcl_oracle(const TriangleMesh& mesh) {
  return std::make_unique<FclOracle>(mesh);
}

}  // namespace hapsim::oracle
