// Stage 2b: dynamic bodies against the other bodies (a ball on the floor, in a gripper, on the
// sheet). A dynamic body is one exact sphere; its sphere tree is that one sphere, so descending
// both bodies' trees only where parent spheres overlap (paper 000 §3.1) is descending the other
// segment's sphere tree where its spheres meet the ball's, then refining exactly on the leaves'
// triangles: SphereTree::contact_within, the query tools use. A sheet answers from its live
// elastic field instead (SheetQuery). Each contact is one spring between the points of closest
// approach, equal and opposite on both bodies (paper 000 §3.2.1), of both materials in series,
// with Coulomb friction; a sheet takes the push as this step's force on it.
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/force/contact_friction.h"
#include "hapsim/force/penalty_force.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>

namespace hapsim::stage {

namespace {

// The contact of sphere (c_world, r) with segment `flat`, or false. `pair` keeps the hint and
// whether they touched last step (only then can the centre be deeper than the radius).
bool sphere_segment_contact(const WorldState& state, const SegmentModel& seg, std::size_t flat,
                            const Vec3& c_world, double r, BodyPairState& pair,
                            SurfacePoint& sp) noexcept {
  const Vec3 c_body = state.X_body_world(seg) * c_world;
  const Box3& bounds = seg.rest_bounds_body;
  if ((c_body - c_body.cwiseMax(bounds.min()).cwiseMin(bounds.max())).squaredNorm() > r * r) {
    return false;
  }
  // A CSG solid or an exact sphere answers from its exact signed distance, a sheet from its live
  // field.
  const bool tree = seg.body_tree && !seg.description->csg && !seg.description->sphere;
  const ProximityQuery& query =
      tree ? static_cast<const ProximityQuery&>(*seg.body_tree) : state.contact_query(seg, flat);
  if (query.contact_within(c_body, r, &sp, &pair.hint)) {
    return sp.signed_distance < r;
  }
  if (!pair.touching || !bounds.contains(c_body)) {
    return false;
  }
  sp = query.closest_point(c_body, &pair.hint);  // pushed deeper than its radius: still inside?
  return sp.found() && sp.signed_distance < 0.0;
}

}  // namespace

// haptic path
void body_contacts(const WorldModel& model, WorldState& state, double /*dt_s*/) noexcept {
  state.body_contact_count = 0;
  state.dropped_body_contacts = 0;
  const std::vector<SegmentModel>& segs = model.segments();
  const std::vector<std::size_t>& dynamic = model.dynamic_bodies();
  for (std::size_t i = 0; i < dynamic.size(); ++i) {
    const std::size_t b = dynamic[i];
    const BodyModel& bm = model.bodies()[b];
    const SegmentModel& own = segs[bm.first_segment];
    const ExactSphere& sphere = *bm.sphere;
    for (std::size_t flat = 0; flat < segs.size(); ++flat) {
      const SegmentModel& seg = segs[flat];
      BodyPairState& pair = state.body_pairs[i * segs.size() + flat];
      // Two dynamic bodies meet once: the lower-numbered one answers for both.
      if (seg.body == b || (seg.dynamic && seg.body < b)) {
        continue;
      }
      BodyState& body = state.bodies[b];
      const Vec3 c_world = body.X_world_body * sphere.center_body;
      SurfacePoint sp;
      if (!sphere_segment_contact(state, seg, flat, c_world, sphere.radius_m, pair, sp)) {
        pair.touching = false;
        pair.stick_body.active = false;
        continue;
      }
      pair.touching = true;
      BodyState& other = state.bodies[seg.body];
      const BodyModel& other_model = model.bodies()[seg.body];
      const double depth = sphere.radius_m - sp.signed_distance;
      const Vec3 n_world = other.X_world_body.linear() * sp.normal;
      const Vec3 point_world = other.X_world_body * sp.point;
      const Vec3 p_ball = c_world - sphere.radius_m * n_world;  // the ball's deepest point
      // Relative to the other body's surface there (static: at rest; a pad: moving with the rig).
      const Vec3 v_rel = body.velocity_at(p_ball, bm.com_body) -
                         other.velocity_at(point_world, other_model.com_body);
      const ContactMaterial material =
          combine_materials(state.body_materials[own.material], state.body_materials[seg.material]);
      const Vec3 f_normal = penalty_force(material, depth, n_world, -v_rel.dot(n_world));
      // Friction: a stick spring from the ball's lowest point to where it stuck on the other body.
      // That point follows the ball's centre, not its material: a ball held this way slides but
      // cannot roll (see the note in docs/architecture.md#contact).
      StickPoint stick{pair.stick_body.active, other.X_world_body * pair.stick_body.p};
      const Vec3 f = f_normal + contact_friction_force(material, f_normal.norm(), n_world, v_rel,
                                                       p_ball, stick);
      pair.stick_body = {stick.active, other.X_body_world * stick.p};
      body.force_world_n += f;
      body.torque_world_nm += (p_ball - body.com_world(bm.com_body)).cross(f);
      // The other body gets the opposite (integrated when dynamic; a pad's is what the rig feels).
      other.force_world_n -= f;
      other.torque_world_nm -= (point_world - other.com_world(other_model.com_body)).cross(f);
      if (seg.sheet) {
        add_sheet_push(state.segments[flat], other.X_body_world, point_world, f);
      }
      if (state.body_contact_count < state.body_contacts.size()) {
        state.body_contacts[state.body_contact_count++] =
            BodyContact{static_cast<std::int32_t>(b),
                        static_cast<std::int32_t>(seg.body),
                        static_cast<std::int32_t>(seg.index_in_body),
                        point_world,
                        n_world,
                        depth,
                        f};
      } else {
        ++state.dropped_body_contacts;
      }
    }
  }
}

}  // namespace hapsim::stage
