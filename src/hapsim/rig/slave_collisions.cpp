// The slave's collisions with what it cannot push back (rig_controller.h): a link, the palm, the
// stem or a pad deeper than RigState::kCollisionDepthM inside the floor, the sheet or another
// static or deformable body, where the real robot would hit the table.
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <array>
#include <utility>

namespace hapsim {

namespace {

// Bounds in the world of a box given in a body frame.
Box3 world_bounds(const Box3& box_body, const Iso3& X_world_body) noexcept {
  const Vec3 c = X_world_body * box_body.center();
  const Vec3 h = X_world_body.linear().cwiseAbs() * (0.5 * box_body.sizes());
  return Box3(c - h, c + h);
}

// Whether `tree`'s mesh, placed in `other`'s frame by X_other_mine, is deeper than
// RigState::kCollisionDepthM inside `other`. The tree is descended only where its spheres reach
// other's surface, the sphere most inside first, so a link through a table finds a leaf inside it
// (a few triangles, its sphere's centre on them) in about (levels × branching) queries; a leaf
// counts when its centre is that deep inside. A link hugging the surface without entering it
// would have every leaf along it tested: after kMaxQueries it is counted as touching (it is
// within a leaf's size of the surface all along). A link wholly inside a body, with no sphere
// reaching its surface, is not seen: it went in through the surface, and was counted then.
bool penetrates(const SphereTree& tree, const Iso3& X_other_mine,
                const ProximityQuery& other) noexcept {
  constexpr int kMaxQueries = 64;
  constexpr std::size_t kMaxSorted = 16;  // children ordered by depth (a tree has 4)
  const auto is_leaf = [&](std::uint32_t n) { return tree.node_children(n).empty(); };
  if (tree.node_count() == 0) {
    return false;
  }
  SurfacePoint sp;
  const Sphere root = tree.node_sphere(0);
  if (!other.contact_within(X_other_mine * root.center, root.radius, &sp)) {
    return false;
  }
  if (is_leaf(0)) {
    return sp.signed_distance < -RigState::kCollisionDepthM;
  }
  std::array<std::uint32_t, 128> stack{};
  std::size_t top = 0;
  stack[top++] = 0;
  int queries = 1;
  while (top > 0) {
    const std::uint32_t n = stack[--top];
    std::array<std::pair<double, std::uint32_t>, kMaxSorted> reaching{};
    std::size_t m = 0;
    for (const std::uint32_t child : tree.node_children(n)) {
      if (++queries > kMaxQueries) {
        return true;
      }
      const Sphere sphere = tree.node_sphere(child);
      if (!other.contact_within(X_other_mine * sphere.center, sphere.radius, &sp)) {
        continue;
      }
      if (is_leaf(child)) {
        if (sp.signed_distance < -RigState::kCollisionDepthM) {
          return true;
        }
      } else if (m < reaching.size()) {
        reaching[m++] = {sp.signed_distance, child};
      } else if (top < stack.size()) {
        stack[top++] = child;
      }
    }
    // The most inside last on the stack: visited next.
    std::sort(reaching.begin(), reaching.begin() + static_cast<std::ptrdiff_t>(m),
              [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t i = 0; i < m && top < stack.size(); ++i) {
      stack[top++] = reaching[i].second;
    }
  }
  return false;
}

}  // namespace

// The slave's collisions with what it cannot push back (the floor, the sheet): its bodies' bounds
// against theirs, then its sphere trees against their surfaces where the bounds meet.
// haptic path
void count_slave_collisions(const WorldModel& model, RigState& rig,
                            const WorldState& state) noexcept {
  TeleopStepResult& r = rig.result;
  r.slave_collisions = 0;
  r.slave_collision_bodies = 0;
  const std::vector<SegmentModel>& segs = model.segments();
  for (const RigState::Collider& c : rig.colliders) {
    const BodyState& body = state.bodies[c.body];
    const Box3 bounds = world_bounds(segs[c.flat].rest_bounds_body, body.X_world_body);
    for (const RigState::Obstacle& o : rig.obstacles) {
      if (!bounds.intersects(o.bounds_world)) {
        continue;
      }
      const SegmentModel& other = segs[o.flat];
      if (penetrates(*segs[c.flat].body_tree, state.bodies[o.body].X_body_world * body.X_world_body,
                     state.contact_query(other, o.flat))) {
        ++r.slave_collisions;
        for (const std::size_t b : {c.body, o.body}) {
          r.slave_collision_bodies |= b < 64 ? std::uint64_t{1} << b : 0;
        }
      }
    }
  }
}

// The slave's bodies that can hit something (links beyond the waist, palm, stem, pads) and the
// bodies they cannot push back (static, deformable), for the place stage's slave collisions.
void find_slave_collision_pairs(const WorldModel& model, RigState& rig) {
  const TeleopRigDescription& d = *rig.description;
  const auto add_collider = [&](std::size_t b) {
    const BodyModel& bm = model.bodies()[b];
    const std::size_t first = bm.first_segment.index();
    for (std::size_t flat = first; flat < first + bm.segment_count; ++flat) {
      const SphereTree* tree = model.segments()[flat].body_tree.get();
      if (tree == nullptr) {
        continue;  // a sheet: no tree (a rig's bodies are kinematic, which always have one)
      }
      rig.colliders.push_back({b, flat});
    }
  };
  // The base and the link the first joint turns (the waist) stand on the robot's mount: only the
  // links beyond, and the gripper, can hit something.
  for (const TeleopRigDescription::SlaveBody& s : d.slave_bodies) {
    if (s.frame >= 1 || s.frame == kToolFrame) {
      add_collider(s.body);
    }
  }
  for (const std::size_t pad : d.pad_body) {
    add_collider(pad);
  }
  for (std::size_t flat = 0; flat < model.segments().size(); ++flat) {
    const SegmentModel& seg = model.segments()[flat];
    const BodyKind kind = model.bodies()[seg.body].kind;
    if (kind != BodyKind::kStatic && kind != BodyKind::kDeformable) {
      continue;
    }
    Box3 bounds_world;
    const Box3& b = seg.rest_bounds_body;
    for (int corner = 0; corner < 8; ++corner) {
      bounds_world.extend(seg.X_world_body * b.corner(static_cast<Box3::CornerType>(corner)));
    }
    rig.obstacles.push_back({seg.body, flat, bounds_world});
  }
}

}  // namespace hapsim
