#include "hapsim/script/scene_palpation_plan.h"

#include "hapsim/core/error.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <cstddef>

namespace hapsim {

PalpationPlan make_scene_palpation(const World& world, const PalpationScriptDescription& script) {
  if (script.targets.empty()) {
    throw Error("palpation script", "has no targets");
  }
  const double radius =
      world.description().tools.empty() ? 0.0 : world.description().tools.front().radius_m;
  std::vector<PalpationTarget> targets;
  ExactBodies exact(world);
  for (const PalpationTargetDescription& t : script.targets) {
    const PalpationAim aimed = aim_palpation_target(world, t, exact);
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
  params.sample_period_s = script.sample_period_s;
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

}  // namespace hapsim
