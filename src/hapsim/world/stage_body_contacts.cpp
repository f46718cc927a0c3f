// Stage 2b: dynamic bodies against the other bodies (a ball on the floor, in a gripper, on the
// sheet; a box on a table, one box on another). Descending both bodies' sphere trees only where
// parent spheres overlap (paper 000 §3.1), then refining exactly:
// - a dynamic exact sphere's tree is that one sphere, so the descent is the other segment's tree
//   where its spheres meet the ball, then its leaves' triangles: SphereTree::contact_within, the
//   query tools use (a CSG solid, an exact sphere or a sheet answers from its exact field);
// - a dynamic mesh descends both trees together (SphereTree::overlapping_leaves, with a skin so
//   vertices that sank in are found), and each vertex of the overlapping leaves of either body
//   is refined against the other body's exact surface: a vertex inside is one penalty spring
//   (vertex against face; edge against edge is not detected). A sheet has no tree: the mesh's
//   vertices over it are tried against its live field.
// Each contact is a spring between the points of closest approach, equal and opposite on both
// bodies (paper 000 §3.2.1), of both materials in series, with Coulomb friction (one stick point
// per pair of segments, at the force-weighted centre of its vertex contacts); a sheet takes the
// push as this step's force on it.
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/force/contact_friction.h"
#include "hapsim/force/penalty_force.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <cmath>

namespace hapsim::stage {

namespace {

// How far inside another body a dynamic mesh's vertex is still found: the leaf descent's margin
// and the vertex query's reach. Penalty contacts between bodies sink in a fraction of a
// millimetre (weight / stiffness); a vertex pushed deeper than this is lost.
constexpr double kVertexSkin_m = 0.005;

// The exact query of segment `flat` for body contact: a mesh's sphere tree (exact, whatever
// method tools use on it), a CSG solid's or exact sphere's signed distance, a sheet's live field.
const ProximityQuery& exact_query(const WorldState& state, const SegmentModel& seg,
                                  std::size_t flat) noexcept {
  const bool tree = seg.body_tree && !seg.description->csg && !seg.description->sphere;
  return tree ? static_cast<const ProximityQuery&>(*seg.body_tree) : state.contact_query(seg, flat);
}

// Two dynamic bodies meet once: an exact sphere answers for itself (its centre and radius are
// exact, its polygonised mesh is not), otherwise the lower-numbered body.
bool answers_for_pair(const WorldModel& model, std::size_t body, const SegmentModel& other) {
  if (!other.dynamic) {
    return true;
  }
  const bool own_sphere = model.bodies()[body].sphere.has_value();
  const bool other_sphere = model.bodies()[other.body].sphere.has_value();
  if (own_sphere != other_sphere) {
    return own_sphere;
  }
  return body < other.body;
}

// The sphere (x − c)² ≤ r² reaches the box (all in one frame).
bool sphere_reaches_box(const Vec3& c, double r, const Box3& box) noexcept {
  return (c - c.cwiseMax(box.min()).cwiseMin(box.max())).squaredNorm() <= r * r;
}

// One pair of segments' contact this step, as friction, the record and a sheet's push need it:
// the dynamic segment A presses at p_a_world on B's surface at p_b_world, along n_world (out of
// B towards A), with normal force f_normal_on_a_n.
struct PairContact {
  Vec3 p_a_world = Vec3::Zero();
  Vec3 p_b_world = Vec3::Zero();
  Vec3 n_world = Vec3::UnitZ();
  double depth_m = 0.0;
  Vec3 f_normal_on_a_n = Vec3::Zero();
  /// The normal force is already on both bodies (a mesh's vertex springs, each where it acts).
  bool normal_applied = false;
  /// What friction is limited by: the sum of the normal forces' sizes (a mesh's vertex forces
  /// may point different ways, as in a groove or a slot), newtons.
  double normal_load_n = 0.0;
  /// A mesh: how far its vertex forces spread around p_a_world (their force-weighted rms
  /// distance), what friction against spinning about the normal acts over. 0 for a sphere.
  double spin_radius_m = 0.0;
};

// When both bodies move, a contact spring between them couples their velocity updates (the
// integrate stage solves them together). haptic path
void couple_penalty(const WorldModel& model, WorldState& state, std::size_t a, std::size_t b,
                    const Vec3& p_a_world, const Vec3& p_b_world, const ContactMaterial& material,
                    const Vec3& n_world, double depth_m, double force_n) noexcept {
  Mat3 S;
  Mat3 D;
  if (model.bodies()[a].dynamic_index >= 0 && model.bodies()[b].dynamic_index >= 0 &&
      penalty_spring(material, n_world, depth_m, force_n, S, D)) {
    state.couple_bodies(model, a, b, p_a_world, p_b_world, S, D);
  }
}

// The contact of sphere (c_world, r) with segment `flat`, or false. `pair` keeps the hint and
// whether they touched last step (only then can the centre be deeper than the radius).
bool sphere_segment_contact(const WorldState& state, const SegmentModel& seg, std::size_t flat,
                            const Vec3& c_world, double r, BodyPairState& pair,
                            SurfacePoint& sp) noexcept {
  const Vec3 c_body = state.X_body_world(seg) * c_world;
  const Box3& bounds = seg.rest_bounds_body;
  if (!sphere_reaches_box(c_body, r, bounds)) {
    return false;
  }
  const ProximityQuery& query = exact_query(state, seg, flat);
  if (query.contact_within(c_body, r, &sp, &pair.hint)) {
    return sp.signed_distance < r;
  }
  if (!pair.touching || !bounds.contains(c_body)) {
    return false;
  }
  sp = query.closest_point(c_body, &pair.hint);  // pushed deeper than its radius: still inside?
  return sp.found() && sp.signed_distance < 0.0;
}

// A dynamic exact sphere against segment `seg`: its centre against the segment's surface.
bool sphere_pair(const WorldModel& model, WorldState& state, const SegmentModel& own_seg,
                 const SegmentModel& seg, std::size_t flat, BodyPairState& pair,
                 PairContact& c) noexcept {
  const std::size_t body = own_seg.body;
  const BodyModel& bm = model.bodies()[body];
  const ExactSphere& sphere = *bm.sphere;
  const BodyState& own = state.bodies[body];
  const Vec3 c_world = own.X_world_body * sphere.center_body;
  SurfacePoint sp;
  if (!sphere_segment_contact(state, seg, flat, c_world, sphere.radius_m, pair, sp)) {
    return false;
  }
  const BodyState& other = state.bodies[seg.body];
  c.depth_m = sphere.radius_m - sp.signed_distance;
  c.n_world = other.X_world_body.linear() * sp.normal;
  c.p_b_world = other.X_world_body * sp.point;
  c.p_a_world = c_world - sphere.radius_m * c.n_world;  // the ball's deepest point
  // Relative to the other body's surface there (static: at rest; a pad: moving with the rig).
  const Vec3 v_rel = own.velocity_at(c.p_a_world, bm.com_body) -
                     other.velocity_at(c.p_b_world, model.bodies()[seg.body].com_body);
  const ContactMaterial material =
      combine_materials(state.body_materials[own_seg.material], state.body_materials[seg.material]);
  c.f_normal_on_a_n = penalty_force(material, c.depth_m, c.n_world, -v_rel.dot(c.n_world));
  c.normal_load_n = c.f_normal_on_a_n.norm();
  if (!seg.sheet) {  // a sheet gives way a step later: its contact stays explicit
    const double f_n = c.f_normal_on_a_n.norm();
    const BodyModel& other_model = model.bodies()[seg.body];
    linearise_penalty(state.bodies[body], bm, c.p_a_world, c.n_world, material, c.depth_m, f_n,
                      other.velocity_at(c.p_b_world, other_model.com_body));
    linearise_penalty(state.bodies[seg.body], other_model, c.p_b_world, c.n_world, material,
                      c.depth_m, f_n, own.velocity_at(c.p_a_world, bm.com_body));
    couple_penalty(model, state, body, seg.body, c.p_a_world, c.p_b_world, material, c.n_world,
                   c.depth_m, f_n);
  }
  return true;
}

// Force `f` on `body` at `p_world`.
void push(BodyState& body, const BodyModel& bm, const Vec3& p_world, const Vec3& f) noexcept {
  body.force_world_n += f;
  body.torque_world_nm += (p_world - body.com_world(bm.com_body)).cross(f);
}

// A dynamic mesh A against segment B, vertex by vertex: the vertices of both that the two trees'
// overlapping leaves hold (B a sheet: all of A's over its bounds), each refined against the
// other's exact surface; every vertex inside is one penalty spring at that vertex.
class MeshPair {
 public:
  MeshPair(const WorldModel& model, WorldState& state, const SegmentModel& a, std::size_t a_flat,
           const SegmentModel& b, std::size_t b_flat, BodyPairState& pair) noexcept
      : model_(model),
        state_(state),
        a_(a),
        b_(b),
        body_a_(state.bodies[a.body]),
        body_b_(state.bodies[b.body]),
        model_a_(model.bodies()[a.body]),
        model_b_(model.bodies()[b.body]),
        query_a_(exact_query(state, a, a_flat)),
        query_b_(exact_query(state, b, b_flat)),
        pair_(pair),
        material_(
            combine_materials(state.body_materials[a.material], state.body_materials[b.material])),
        X_b_a_(body_b_.X_body_world * body_a_.X_world_body),
        X_a_b_(body_a_.X_body_world * body_b_.X_world_body),
        vertex_a_pass_(state.segments[a_flat].vertex_pass),
        vertex_b_pass_(state.segments[b_flat].vertex_pass),
        bounds_a_(a.rest_bounds_body),
        bounds_b_(b.rest_bounds_body) {
    bounds_a_.extend(bounds_a_.min() - Vec3::Constant(kVertexSkin_m));
    bounds_a_.extend(bounds_a_.max() + Vec3::Constant(kVertexSkin_m));
    bounds_b_.extend(bounds_b_.min() - Vec3::Constant(kVertexSkin_m));
    bounds_b_.extend(bounds_b_.max() + Vec3::Constant(kVertexSkin_m));
  }

  // Finds and applies this step's vertex springs; false when none.
  bool run(PairContact& c) noexcept {
    const Sphere root = a_.body_tree->node_sphere(0);
    if (!sphere_reaches_box(X_b_a_ * root.center, root.radius + kVertexSkin_m,
                            b_.rest_bounds_body)) {
      return false;
    }
    const std::uint32_t pass = next_pass();
    const TriangleMesh& mesh_a = a_.description->mesh;
    if (b_.body_tree) {
      std::vector<LeafPair>& leaves = state_.leaf_pairs;
      leaves.clear();
      if (!b_.body_tree->overlapping_leaves(*a_.body_tree, X_b_a_, leaves, nullptr, kVertexSkin_m,
                                            leaves.capacity())) {
        ++state_.dropped_body_contacts;
      }
      const TriangleMesh& mesh_b = b_.description->mesh;
      for (const LeafPair& lp : leaves) {
        for (const std::uint32_t t : a_.body_tree->leaf_triangles(lp.leaf_b)) {
          for (const std::uint32_t v : mesh_a.triangles[t]) {
            if (vertex_a_pass_[v] != pass) {
              vertex_a_pass_[v] = pass;
              try_vertex_of_a(mesh_a.vertices[v]);
            }
          }
        }
        for (const std::uint32_t t : b_.body_tree->leaf_triangles(lp.leaf_a)) {
          for (const std::uint32_t v : mesh_b.triangles[t]) {
            if (vertex_b_pass_[v] != pass) {
              vertex_b_pass_[v] = pass;
              try_vertex_of_b(mesh_b.vertices[v]);
            }
          }
        }
      }
    } else {
      for (const Vec3& v_a : mesh_a.vertices) {  // a sheet: its field against A's vertices
        try_vertex_of_a(v_a);
      }
    }
    if (weight_ <= 0.0) {
      return false;
    }
    c.p_a_world = weighted_point_world_ / weight_;
    c.p_b_world = c.p_a_world;
    c.spin_radius_m =
        std::sqrt(std::max(0.0, weighted_square_m2_ / weight_ - c.p_a_world.squaredNorm()));
    // The friction plane: across the summed force, unless the vertex forces mostly cancel (a
    // body pinched in a slot), then across the hardest-pressed vertex's normal.
    const double n_norm = f_normal_on_a_.norm();
    c.n_world = n_norm >= 0.5 * force_sizes_n_ && n_norm > 0.0 ? Vec3(f_normal_on_a_ / n_norm)
                                                               : hardest_normal_;
    c.normal_load_n = force_sizes_n_;
    c.depth_m = deepest_m_;
    c.f_normal_on_a_n = f_normal_on_a_;
    c.normal_applied = true;
    return true;
  }

 private:
  std::uint32_t next_pass() noexcept {
    if (++state_.vertex_pass == 0) {  // wrapped: no vertex may keep a stale pass number
      for (SegmentState& seg : state_.segments) {
        std::fill(seg.vertex_pass.begin(), seg.vertex_pass.end(), 0);
      }
      state_.vertex_pass = 1;
    }
    return state_.vertex_pass;
  }

  // A's vertex (A's frame) inside B: pushed out along B's normal.
  void try_vertex_of_a(const Vec3& v_a) noexcept {
    const Vec3 p_b = X_b_a_ * v_a;
    if (!bounds_b_.contains(p_b)) {
      return;
    }
    SurfacePoint sp;
    if (!query_b_.contact_within(p_b, kVertexSkin_m, &sp, &pair_.hint) ||
        !(sp.signed_distance < 0.0)) {
      return;
    }
    const Vec3 p_world = body_b_.X_world_body * p_b;
    const Vec3 n_world = body_b_.X_world_body.linear() * sp.normal;  // out of B, towards A
    const Vec3 v_rel = body_a_.velocity_at(p_world, model_a_.com_body) -
                       body_b_.velocity_at(p_world, model_b_.com_body);
    add(p_world, n_world, -sp.signed_distance,
        penalty_force(material_, -sp.signed_distance, n_world, -v_rel.dot(n_world)));
  }

  // B's vertex (B's frame) inside A: A pushed away along minus A's normal there.
  void try_vertex_of_b(const Vec3& v_b) noexcept {
    const Vec3 p_a = X_a_b_ * v_b;
    if (!bounds_a_.contains(p_a)) {
      return;
    }
    SurfacePoint sp;
    if (!query_a_.contact_within(p_a, kVertexSkin_m, &sp, &pair_.hint_own) ||
        !(sp.signed_distance < 0.0)) {
      return;
    }
    const Vec3 p_world = body_a_.X_world_body * p_a;
    const Vec3 n_world = -(body_a_.X_world_body.linear() * sp.normal);  // out of B, towards A
    const Vec3 v_rel = body_a_.velocity_at(p_world, model_a_.com_body) -
                       body_b_.velocity_at(p_world, model_b_.com_body);
    add(p_world, n_world, -sp.signed_distance,
        penalty_force(material_, -sp.signed_distance, n_world, -v_rel.dot(n_world)));
  }

  // One vertex spring: f on A at p_world, the opposite on B.
  void add(const Vec3& p_world, const Vec3& n_world, double depth_m, const Vec3& f) noexcept {
    push(body_a_, model_a_, p_world, f);
    push(body_b_, model_b_, p_world, -f);
    if (!b_.sheet) {  // a sheet gives way a step later: its contact stays explicit
      linearise_penalty(body_a_, model_a_, p_world, n_world, material_, depth_m, f.norm(),
                        body_b_.velocity_at(p_world, model_b_.com_body));
      linearise_penalty(body_b_, model_b_, p_world, n_world, material_, depth_m, f.norm(),
                        body_a_.velocity_at(p_world, model_a_.com_body));
      couple_penalty(model_, state_, a_.body, b_.body, p_world, p_world, material_, n_world,
                     depth_m, f.norm());
    }
    f_normal_on_a_ += f;
    const double f_n = f.norm();
    force_sizes_n_ += f_n;
    if (f_n >= hardest_n_) {
      hardest_n_ = f_n;
      hardest_normal_ = n_world;
    }
    // The stick point sits where the springs push, weighted by how hard (a bare touch: evenly).
    const double w = f.norm() + 1e-12;
    weighted_point_world_ += w * p_world;
    weighted_square_m2_ += w * p_world.squaredNorm();
    weight_ += w;
    deepest_m_ = std::max(deepest_m_, depth_m);
  }

  const WorldModel& model_;
  WorldState& state_;
  const SegmentModel& a_;
  const SegmentModel& b_;
  BodyState& body_a_;
  BodyState& body_b_;
  const BodyModel& model_a_;
  const BodyModel& model_b_;
  const ProximityQuery& query_a_;
  const ProximityQuery& query_b_;
  BodyPairState& pair_;
  ContactMaterial material_;
  Iso3 X_b_a_;
  Iso3 X_a_b_;
  std::vector<std::uint32_t>& vertex_a_pass_;
  std::vector<std::uint32_t>& vertex_b_pass_;
  Box3 bounds_a_;
  Box3 bounds_b_;
  Vec3 f_normal_on_a_ = Vec3::Zero();
  double force_sizes_n_ = 0.0;
  double hardest_n_ = 0.0;
  Vec3 hardest_normal_ = Vec3::UnitZ();
  Vec3 weighted_point_world_ = Vec3::Zero();
  double weighted_square_m2_ = 0.0;
  double weight_ = 0.0;
  double deepest_m_ = 0.0;
};

// A mesh's contact spread over an area resists spinning about the normal (one stick point does
// not): viscous, the tangential damping acting at the spread's radius, up to Coulomb's μd·N at
// that radius. It stops a box spinning on a table; a steady torque below the limit creeps.
// Returns the damper it linearised (zero when none), for two dynamic bodies to couple.
Mat3 spin_friction(BodyState& own, BodyState& other, const PairContact& c,
                   const ContactMaterial& material, bool explicit_only) noexcept {
  const double limit_nm = material.dynamic_friction * c.normal_load_n * c.spin_radius_m;
  const double b_nms = material.damping_n_s_per_m * c.spin_radius_m * c.spin_radius_m;
  if (!(limit_nm > 0.0) || !(b_nms > 0.0) || !std::isfinite(b_nms)) {
    return Mat3::Zero();
  }
  const double spin_rad_per_s = (own.w_world - other.w_world).dot(c.n_world);
  const double viscous_nm = b_nms * spin_rad_per_s;
  const double torque_nm = std::clamp(viscous_nm, -limit_nm, limit_nm);
  own.torque_world_nm -= torque_nm * c.n_world;
  other.torque_world_nm += torque_nm * c.n_world;
  if (explicit_only || std::abs(viscous_nm) >= limit_nm) {
    return Mat3::Zero();  // sliding at the Coulomb limit: no damper to take implicitly
  }
  // A pure rotation about n: J = [0, n] for own, the same for the other (its ω enters with −).
  Mat3 nn = b_nms * c.n_world * c.n_world.transpose();
  if (own.dynamic) {
    own.damping_6.bottomRightCorner<3, 3>() += nn;
  }
  if (other.dynamic) {
    other.damping_6.bottomRightCorner<3, 3>() += nn;
  }
  return nn;
}

// Friction at the pair's pressing point, the forces on both bodies, a sheet's push and the record.
void finish_pair(const WorldModel& model, WorldState& state, const SegmentModel& own_seg,
                 const SegmentModel& seg, std::size_t flat, BodyPairState& pair,
                 const PairContact& c) noexcept {
  const std::size_t body = own_seg.body;
  BodyState& own = state.bodies[body];
  BodyState& other = state.bodies[seg.body];
  const BodyModel& own_model = model.bodies()[body];
  const BodyModel& other_model = model.bodies()[seg.body];
  // Friction holds A's pressing point: a sphere's deepest point (it follows the ball's centre,
  // not its material, so a ball held this way slides but cannot roll: see the note in
  // docs/architecture.md#contact); a mesh's material point where it first stuck, so that the
  // spread of its vertex forces shifting as it rocks does not stretch the stick spring. A mesh
  // contact that wandered off that point (rolled, tumbled) sticks anew.
  Vec3 p_friction_world = c.p_a_world;
  if (c.normal_applied && pair.stick_body.active) {
    const Vec3 held_world = own.X_world_body * pair.stick_own_body;
    if ((held_world - c.p_a_world).squaredNorm() <= kVertexSkin_m * kVertexSkin_m) {
      p_friction_world = held_world;
    } else {
      pair.stick_body.active = false;
    }
  }
  const Vec3& p_other_world = c.normal_applied ? p_friction_world : c.p_b_world;
  const Vec3 v_rel = own.velocity_at(p_friction_world, own_model.com_body) -
                     other.velocity_at(p_other_world, other_model.com_body);
  const ContactMaterial material =
      combine_materials(state.body_materials[own_seg.material], state.body_materials[seg.material]);
  // A stick spring from that point to where it stuck on the other body.
  StickPoint stick{pair.stick_body.active, other.X_world_body * pair.stick_body.p};
  const Vec3 f_friction =
      contact_friction_force(material, c.normal_load_n, c.n_world, v_rel, p_friction_world, stick);
  pair.stick_body = {stick.active, other.X_body_world * stick.p};
  pair.stick_own_body = own.X_body_world * p_friction_world;
  if (!seg.sheet) {
    const double f_n = c.normal_load_n;
    linearise_friction(own, own_model, p_friction_world, c.n_world, material, f_n, f_friction,
                       other.velocity_at(p_other_world, other_model.com_body));
    linearise_friction(other, other_model, p_other_world, c.n_world, material, f_n, f_friction,
                       own.velocity_at(p_friction_world, own_model.com_body));
    Mat3 S;
    Mat3 D;
    if (own_model.dynamic_index >= 0 && other_model.dynamic_index >= 0 &&
        friction_spring(material, c.n_world, f_n, f_friction, S, D)) {
      state.couple_bodies(model, body, seg.body, p_friction_world, p_other_world, S, D);
    }
  }
  // What is not on the bodies yet: friction, and for a sphere its normal force too. The other
  // body gets the opposite (integrated when dynamic; a pad's is what the rig feels).
  if (c.normal_applied) {
    push(own, own_model, p_friction_world, f_friction);
    push(other, other_model, p_friction_world, -f_friction);
  } else {
    const Vec3 f = c.f_normal_on_a_n + f_friction;
    push(own, own_model, c.p_a_world, f);
    push(other, other_model, c.p_b_world, -f);
  }
  if (c.spin_radius_m > 0.0) {
    const Mat3 spin_damper = spin_friction(own, other, c, material, seg.sheet);
    if (own_model.dynamic_index >= 0 && other_model.dynamic_index >= 0 &&
        !spin_damper.isZero(0.0)) {
      state.couple_rotations(model, body, seg.body, spin_damper);
    }
  }
  const Vec3 f_total = c.f_normal_on_a_n + f_friction;
  if (seg.sheet) {
    add_sheet_push(state.segments[flat], other.X_body_world, c.p_b_world, f_total);
  }
  if (state.body_contact_count < state.body_contacts.size()) {
    state.body_contacts[state.body_contact_count++] = BodyContact{
        BodyIndex{body}, BodyIndex{seg.body}, seg.index_in_body, c.p_b_world, c.n_world, c.depth_m,
        f_total};
  } else {
    ++state.dropped_body_contacts;
  }
}

}  // namespace

// haptic path
void body_contacts(const WorldModel& model, WorldState& state, double /*dt_s*/) noexcept {
  state.body_contact_count = 0;
  state.dropped_body_contacts = 0;
  const std::vector<SegmentModel>& segs = model.segments();
  const std::vector<std::size_t>& dynamic = model.dynamic_segments();
  for (std::size_t i = 0; i < dynamic.size(); ++i) {
    const std::size_t own_flat = dynamic[i];
    const SegmentModel& own = segs[own_flat];
    const std::size_t b = own.body;
    for (std::size_t flat = 0; flat < segs.size(); ++flat) {
      const SegmentModel& seg = segs[flat];
      if (seg.body == b || !answers_for_pair(model, b, seg)) {
        continue;
      }
      BodyPairState& pair = state.body_pairs[i * segs.size() + flat];
      PairContact c;
      const bool touching = model.bodies()[b].sphere
                                ? sphere_pair(model, state, own, seg, flat, pair, c)
                                : MeshPair(model, state, own, own_flat, seg, flat, pair).run(c);
      pair.touching = touching;
      if (!touching) {
        pair.stick_body.active = false;
        continue;
      }
      finish_pair(model, state, own, seg, flat, pair, c);
    }
  }
}

}  // namespace hapsim::stage
