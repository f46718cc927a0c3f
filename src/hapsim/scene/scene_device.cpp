#include "hapsim/scene/scene_device.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/device/device_profile.h"
#include "hapsim/device/trajectory.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hapsim {
namespace {

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

// Exact rest-surface queries of a body's segments, built once per body: aiming must not depend on
// the world's (possibly approximate, near-surface-only) contact method.
class ExactBodies {
 public:
  explicit ExactBodies(const World& world) : world_(world) {}
  const std::vector<std::unique_ptr<MeshBvh>>& body(std::size_t b) {
    auto& bvhs = cache_[b];
    if (bvhs.empty()) {
      for (const SegmentDescription& s : world_.description().bodies[b].segments) {
        bvhs.push_back(std::make_unique<MeshBvh>(s.mesh));
      }
    }
    return bvhs;
  }

 private:
  const World& world_;
  std::map<std::size_t, std::vector<std::unique_ptr<MeshBvh>>> cache_;
};

PalpationAim aim(const World& world, const PalpationTargetDescription& target, ExactBodies& exact) {
  const std::size_t body = find_body(world, target.body);
  const std::size_t segment = find_segment(world, body, target.segment);
  const BodyDescription& bd = world.description().bodies[body];
  const TriangleMesh& mesh = bd.segments[segment].mesh;
  Vec3 centroid_body = Vec3::Zero();
  for (const Vec3& v : mesh.vertices) {
    centroid_body += v;
  }
  centroid_body /= static_cast<double>(mesh.vertex_count());
  const Vec3 centroid_world = bd.X_world_body * centroid_body;
  const double norm = target.from_world.norm();
  if (!(norm > 0.0) || !target.from_world.allFinite()) {
    throw Error("palpation target '" + target.segment + "'", "needs a non-zero 'from' direction");
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
  const std::string where = "palpation target '" + target.segment + "'";
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
                         "given and the segment's centroid");
}

}  // namespace

PalpationAim aim_palpation_target(const World& world, const PalpationTargetDescription& target) {
  ExactBodies exact(world);
  return aim(world, target, exact);
}

PalpationPlan make_scene_palpation(const World& world, const PalpationScriptDescription& script) {
  if (script.targets.empty()) {
    throw Error("palpation script", "has no targets");
  }
  const double radius =
      world.description().tools.empty() ? 0.0 : world.description().tools.front().radius_m;
  std::vector<PalpationTarget> targets;
  ExactBodies exact(world);
  for (const PalpationTargetDescription& t : script.targets) {
    const PalpationAim aimed = aim(world, t, exact);
    const Vec3 from = t.from_world.normalized();
    PalpationTarget target;
    target.p_world = aimed.surface_world + from * radius;  // the tool sphere just touching
    target.press_dir_world = -from;
    target.depth_m = t.depth_m;
    target.hold_s = t.hold_s;
    targets.push_back(target);
  }
  PalpationParams params;
  params.standoff_m = script.standoff_m;
  params.move_s = script.move_s;
  params.approach_s = script.approach_s;
  params.press_s = script.press_s;
  params.release_s = script.release_s;
  if (script.has_around_axis) {
    // The cylinder round the axis through the centre of the targeted bodies that clears every
    // vertex of them, plus the farthest tool sphere from the device point, plus the stand-off.
    const Vec3 axis = script.around_axis_world.normalized();
    std::vector<std::size_t> bodies;
    for (const PalpationTargetDescription& t : script.targets) {
      bodies.push_back(find_body(world, t.body));
    }
    std::sort(bodies.begin(), bodies.end());
    bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
    Box3 box;
    for (const std::size_t b : bodies) {
      const BodyDescription& body = world.description().bodies[b];
      for (const SegmentDescription& seg : body.segments) {
        for (const Vec3& v : seg.mesh.vertices) {
          box.extend(body.X_world_body * v);
        }
      }
    }
    const Vec3 c = box.center();
    double body_r = 0.0;
    for (const std::size_t b : bodies) {
      const BodyDescription& body = world.description().bodies[b];
      for (const SegmentDescription& seg : body.segments) {
        for (const Vec3& v : seg.mesh.vertices) {
          const Vec3 d = body.X_world_body * v - c;
          body_r = std::max(body_r, (d - d.dot(axis) * axis).norm());
        }
      }
    }
    double tool_r = 0.0;
    for (const ToolDescription& tool : world.description().tools) {
      tool_r = std::max(tool_r, tool.offset_device.norm() + tool.radius_m);
    }
    params.around_point_world = c;
    params.around_axis_world = axis;
    params.around_radius_m = body_r + tool_r + script.standoff_m;
  }
  const Vec3 first_from = script.targets.front().from_world.normalized();
  params.start_p_world = targets.front().p_world + first_from * (script.standoff_m + 0.03);
  return make_palpation_plan(targets, params);
}

std::unique_ptr<SimulatedDevice> make_scene_device(
    const SceneDescription& scene, const World& world,
    const std::optional<std::filesystem::path>& trajectory_override) {
  const DeviceProfile& profile = device_profile(scene.device.profile);
  if (trajectory_override) {
    return std::make_unique<SimulatedDevice>(profile, load_trajectory_csv(*trajectory_override));
  }
  if (!scene.device.trajectory_file.empty()) {
    return std::make_unique<SimulatedDevice>(profile,
                                             load_trajectory_csv(scene.device.trajectory_file));
  }
  if (scene.device.has_palpation) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_palpation(world, scene.device.palpation).trajectory);
  }
  throw Error(scene.file.string() + ": /device",
              "expected a 'trajectory' file or a 'palpation' script for the simulated device");
}

}  // namespace hapsim
