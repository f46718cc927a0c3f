#include "hapsim/script/palpation_aim.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/world/world.h"

#include <cmath>

namespace hapsim {

std::size_t find_body(const World& world, const std::string& name) {
  const auto& bodies = world.description().bodies;
  if (name.empty() && bodies.size() == 1) {
    return 0;
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    if (bodies[b].name == name) {
      return b;
    }
  }
  throw Error("palpation target", "no body named '" + name + "'");
}

std::size_t find_segment(const World& world, std::size_t body, const std::string& name) {
  const auto& segments = world.description().bodies[body].segments;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (segments[s].name == name) {
      return s;
    }
  }
  throw Error("palpation target",
              "body '" + world.description().bodies[body].name + "' has no segment '" + name + "'");
}

ExactBodies::ExactBodies(const World& world) : world_(world) {}

ExactBodies::~ExactBodies() = default;

const std::vector<std::unique_ptr<MeshBvh>>& ExactBodies::body(std::size_t b) {
  auto& bvhs = cache_[b];
  if (bvhs.empty()) {
    for (const SegmentDescription& s : world_.description().bodies[b].segments) {
      bvhs.push_back(std::make_unique<MeshBvh>(s.mesh));
    }
  }
  return bvhs;
}

PalpationAim aim_palpation_target(const World& world, const PalpationTargetDescription& target) {
  ExactBodies exact(world);
  return aim_palpation_target(world, target, exact);
}

PalpationAim aim_palpation_target(const World& world, const PalpationTargetDescription& target,
                                  ExactBodies& exact) {
  const std::size_t body = find_body(world, target.body);
  const BodyDescription& bd = world.description().bodies[body];
  std::size_t segment = 0;
  Vec3 centroid_world;
  if (target.toward_world) {
    centroid_world = *target.toward_world;
    if (!target.segment.empty()) {
      segment = find_segment(world, body, target.segment);
    }
  } else {
    segment = find_segment(world, body, target.segment);
    const TriangleMesh& mesh = bd.segments[segment].mesh;
    Vec3 centroid_body = Vec3::Zero();
    for (const Vec3& v : mesh.vertices) {
      centroid_body += v;
    }
    centroid_body /= static_cast<double>(mesh.vertex_count());
    centroid_world = bd.X_world_body * centroid_body;
  }
  const std::string where =
      "palpation target '" + (target.segment.empty() ? target.body : target.segment) + "'";
  const double norm = target.from_world.norm();
  if (!(norm > 0.0) || !target.from_world.allFinite()) {
    throw Error(where, "needs a non-zero 'from' direction");
  }
  const Vec3 from = target.from_world / norm;
  // Start outside everything of the body, then trace towards the centroid: each step moves by
  // the distance to the nearest surface, so no surface can be skipped.
  Box3 all;
  for (const SegmentDescription& s : bd.segments) {
    all.extend(s.mesh.bounds());
  }
  const double reach = 2.0 * all.diagonal().norm() + 0.1;
  Vec3 p = centroid_world + from * reach;
  const Iso3 X_body_world = bd.X_world_body.inverse();
  for (int iteration = 0; iteration < 10000; ++iteration) {
    double nearest = kInf;
    std::size_t nearest_segment = segment;
    for (std::size_t s = 0; s < bd.segments.size(); ++s) {
      const SurfacePoint sp = exact.body(body)[s]->closest_point(X_body_world * p);
      if (std::abs(sp.signed_distance) < nearest) {
        nearest = std::abs(sp.signed_distance);
        nearest_segment = s;
      }
    }
    if (nearest < 1e-6) {
      return PalpationAim{p, nearest_segment};
    }
    p -= from * nearest;
    if ((p - centroid_world).dot(from) < 0.0) {
      break;  // passed the centroid without meeting a surface
    }
  }
  throw Error(where, "no surface of body '" + bd.name + "' lies between the direction " +
                         "given and " +
                         (target.toward_world ? "the point toward_m" : "the segment's centroid"));
}

}  // namespace hapsim
