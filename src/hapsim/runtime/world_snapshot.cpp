#include "hapsim/runtime/world_snapshot.h"

#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/rig/rig_controller.h"

namespace hapsim {

WorldSnapshot make_world_snapshot(const World& world) {
  const WorldDescription& d = world.description();
  WorldSnapshot s;
  s.tools.resize(d.tools.size());
  s.tool_force_n.assign(d.tools.size(), 0.0);
  // Room for as many contacts as a step can report (the world's buffer size is not public:
  // tools × (proxy contacts + penalty segments) bounds it).
  s.contacts.resize(d.tools.size() * (static_cast<std::size_t>(GodObject::kMaxContacts) +
                                      world.flat_segment_count()));
  s.positions_body.resize(world.flat_segment_count());
  s.deflection_m.assign(world.flat_segment_count(), 0.0);
  s.positions_version.assign(world.flat_segment_count(), 0);
  s.body_poses_world.resize(d.bodies.size());
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    s.body_poses_world[b] = world.body_pose(b);
    if (const VirtualSheet* sheet = world.sheet(b)) {
      const std::vector<Vec3>& vertices = sheet->mesh().vertices;
      std::vector<float>& xyz =
          s.positions_body[world.flat_segment(BodyIndex{b}, LocalSegment{0}).index()];
      xyz.resize(3 * vertices.size());
      for (std::size_t v = 0; v < vertices.size(); ++v) {
        for (int k = 0; k < 3; ++k) {
          xyz[3 * v + static_cast<std::size_t>(k)] = static_cast<float>(vertices[v][k]);
        }
      }
      continue;
    }
    for (std::size_t seg = 0; seg < d.bodies[b].segments.size(); ++seg) {
      const VertexDeflection* deflection = world.deflection(b, seg);
      if (deflection == nullptr) {
        continue;
      }
      const TriangleMesh& mesh = deflection->mesh();
      std::vector<float>& xyz =
          s.positions_body[world.flat_segment(BodyIndex{b}, LocalSegment{seg}).index()];
      xyz.resize(3 * mesh.vertices.size());
      for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
        for (int k = 0; k < 3; ++k) {
          xyz[3 * v + static_cast<std::size_t>(k)] = static_cast<float>(mesh.vertices[v][k]);
        }
      }
      s.deflection_m[world.flat_segment(BodyIndex{b}, LocalSegment{seg}).index()] =
          deflection->max_deflection_m();
    }
  }
  if (rig_state(world) != nullptr) {
    s.teleop = make_teleop_snapshot(world);
  }
  return s;
}

}  // namespace hapsim
