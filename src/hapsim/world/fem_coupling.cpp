#include "hapsim/world/fem_coupling.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/deform/fem_body_description.h"
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/world/passivity_floor.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

namespace hapsim {

struct FemCoupling::Body {
  std::size_t world_body = 0;
  std::size_t flat_segment = 0;
  Iso3 X_world_body = Iso3::Identity();
  Iso3 X_body_world = Iso3::Identity();
  const FemBodyDescription* description = nullptr;
  std::unique_ptr<FemBody> fem;
  /// The segment's surface as it is now (body frame): the rest mesh with moved vertices.
  TriangleMesh surface;
  /// Boundary surface: the tet node of each surface vertex; embedded: each vertex's tet.
  std::vector<std::uint32_t> node_of_vertex;
  std::vector<TetEmbedding> embedding;
  /// The surface at rest and its BVH: a contact is a material point of the tissue, found on the
  /// rest surface and followed as it moves (see update_body).
  TriangleMesh rest_surface;
  std::unique_ptr<MeshBvh> rest_bvh;
  double patch_radius_m = 0.004;
  double margin_m = 0.01;
  /// Per tool: the node weights of its contact patch from the last update (where its load goes
  /// next) and its query hint.
  std::array<std::vector<FemNodeWeight>, kMaxTools> patch;
  std::array<QueryHint, kMaxTools> hints{};
  /// Per tool: its patch's weighted displacement at the last update (body frame), to find the
  /// same material point again when the tool has pushed the surface in.
  std::array<Vec3, kMaxTools> patch_shift;
  /// Per tool: the shift the material point's search last took off the tool's position, its last
  /// step, and the share of a step it takes (1 until the steps reverse; see update_body).
  struct QueryShift {
    Vec3 shift = Vec3::Zero();
    Vec3 last_step = Vec3::Zero();
    double relaxation = 1.0;
  };
  std::array<QueryShift, kMaxTools> query{};
  /// Per tool, quasi-static only: the last update's load and its patch's displacement along the
  /// normal, and how much softer than compliance_along the tissue answered a change of load
  /// (see update_body).
  struct Secant {
    bool valid = false;
    double load_n = 0.0;
    double normal_shift_m = 0.0;
    double softening = 1.0;
  };
  std::array<Secant, kMaxTools> secant{};
  /// Per surface vertex: the strain stiffening's rate, 1/m: E₁/E₀ of the tissue under it over the
  /// tissue's thickness there (fem_stiffening_per_m); 0 where the tissue is linear.
  std::vector<double> stiffening_per_m;
  /// Per tool, linear elasticity only: the last compliance_along solved, and where (the contact's
  /// rest point and normal, body frame), reused while the contact stays there (update_body).
  struct Compliance {
    bool valid = false;
    Vec3 point = Vec3::Zero();
    Vec3 normal = Vec3::Zero();
    double m_per_n = 0.0;
  };
  std::array<Compliance, kMaxTools> compliance{};
  /// Per tool: its patch's stiffening rate and rest normal (body frame) at the last update.
  std::array<double, kMaxTools> patch_stiffening_per_m{};
  std::array<Vec3, kMaxTools> patch_normal;
  std::vector<FemNodeForce> loads;
  /// Stress for display: per tet, and per surface vertex; a boundary vertex's tets (CSR).
  std::vector<double> tet_von_mises_pa;
  FemSurfaceFrame frame;
  std::vector<std::uint32_t> vertex_tets_start;
  std::vector<std::uint32_t> vertex_tets;
};

namespace {

// The nodes of a FEM body held fixed: by index, by plane, and by other bodies' segments.
std::vector<std::uint32_t> fem_fixed_nodes(const WorldModel& model, const BodyDescription& body,
                                           const FemBodyDescription& fem) {
  std::set<std::uint32_t> fixed(fem.fixed_nodes.begin(), fem.fixed_nodes.end());
  const TetMesh& tets = fem.tets;
  if (fem.fixed_below_z_m) {
    for (std::size_t i = 0; i < tets.nodes.size(); ++i) {
      if (tets.nodes[i].z() <= *fem.fixed_below_z_m) {
        fixed.insert(static_cast<std::uint32_t>(i));
      }
    }
  }
  const WorldDescription& d = model.description();
  for (const FemAttachment& a : fem.attached_to) {
    bool found_body = false;
    for (std::size_t ob = 0; ob < d.bodies.size(); ++ob) {
      if (d.bodies[ob].name != a.body) {
        continue;
      }
      found_body = true;
      std::size_t matched = 0;
      for (std::size_t s = 0; s < d.bodies[ob].segments.size(); ++s) {
        if (!a.segment.empty() && d.bodies[ob].segments[s].name != a.segment) {
          continue;
        }
        ++matched;
        const SegmentModel& seg =
            model.segments()[model.flat_segment(BodyIndex{ob}, LocalSegment{s}).index()];
        // Both bodies stand still (a FEM body and what holds it are not dynamic): one transform.
        const Iso3 X_other_fem = seg.X_body_world * body.X_world_body;
        for (std::size_t i = 0; i < tets.nodes.size(); ++i) {
          const SurfacePoint sp = seg.rest_query->closest_point(X_other_fem * tets.nodes[i]);
          if (sp.found() && sp.signed_distance <= a.within_m) {
            fixed.insert(static_cast<std::uint32_t>(i));
          }
        }
      }
      if (matched == 0) {
        throw Error(a.where.empty() ? fem.source : a.where, "attached_to names segment '" +
                                                                a.segment + "' of body '" + a.body +
                                                                "', which has no such segment");
      }
    }
    if (!found_body) {
      throw Error(a.where.empty() ? fem.source : a.where,
                  "attached_to names body '" + a.body + "', which the world lacks");
    }
  }
  if (fixed.empty()) {
    throw Error(fem.source + " (body '" + body.name + "')",
                "no node is fixed: give fixed nodes, a plane or a body it is attached to (a free "
                "FEM body has no rest position to return to); the attachments given reach no node");
  }
  return {fixed.begin(), fixed.end()};
}

// The secant softening of a quasi-static contact (update_body): measured from a load change of at
// least 1 mN and 2 % of the load, at most ten times softer than compliance_along.
constexpr double kFemSecantMinLoadStepN = 1e-3;
constexpr double kFemSecantMinLoadFraction = 0.02;
constexpr double kFemMaxSoftening = 10.0;

// A linear body's compliance at a contact is solved again only when the contact's rest point has
// moved this far, or its normal turned this much, since the last solve: the solve costs as much
// as the FEM step itself (a held fingertip doubled the update, 8 → 16 ms on the 26k knee), and
// over a patch 12 mm across the compliance barely changes in half a millimetre.
constexpr double kFemComplianceReuseM = 0.5e-3;
constexpr double kFemComplianceReuseCos = 0.9994;  // 2°

// The material point's search (update_body) is a fixed-point iteration, X = closest(p - u(X)),
// one step per update: where the displacement under the patch changes faster than the patch
// moves (a stretch of coarse surface, the patch's nodes few and far), it overshoots and the
// contact flips between two points every update (1.6 mm apart, 1.4 and 5.9 N: the
// tele-palpation's second press on the 20k knee). A step that reverses the last one by more than
// this halves the share of each step taken, down to the smallest; a contact that never reverses
// takes whole steps, as before.
constexpr double kFemQueryReversalM = 1e-4;
constexpr double kFemQueryMinRelaxation = 1.0 / 16.0;

// The thinnest tissue a stiffening rate is taken over: a surface vertex on (or at) a fixed node
// would otherwise stiffen without bound.
constexpr double kFemMinThicknessM = 1e-3;

// Per surface vertex, the rate of Zheng & Mak's strain stiffening E(ε) = E₀ + E₁·ε per metre of
// indentation: E₁/E₀ of the region under it (an embedded vertex: its tet's; a boundary vertex: the
// mean over its tets) over the tissue's thickness there, taken as the distance to the nearest
// fixed node (tissue held on bone: how deep the bone lies; a block on a table: its height).
std::vector<double> fem_stiffening_per_m(const FemBodyDescription& fd, const FemBody& fem,
                                         const TriangleMesh& rest_surface,
                                         const std::vector<TetEmbedding>& embedding,
                                         const std::vector<std::uint32_t>& vertex_tets_start,
                                         const std::vector<std::uint32_t>& vertex_tets) {
  const TetMesh& tets = fd.tets;
  std::vector<double> ratio_of_tet(tets.tets.size(), 0.0);
  bool any = false;
  for (std::size_t t = 0; t < tets.tets.size(); ++t) {
    for (const FemRegionMaterial& m : fd.materials) {
      if (m.region == tets.region(t) && m.material.youngs_modulus_pa > 0.0) {
        ratio_of_tet[t] = m.material.nonlinear_modulus_pa / m.material.youngs_modulus_pa;
        any = any || ratio_of_tet[t] > 0.0;
      }
    }
  }
  std::vector<double> out(rest_surface.vertices.size(), 0.0);
  if (!any) {
    return out;
  }
  const std::vector<std::uint32_t>& fixed = fem.fixed_nodes();
  for (std::size_t v = 0; v < out.size(); ++v) {
    double ratio = 0.0;
    if (!embedding.empty()) {
      ratio = ratio_of_tet[embedding[v].tet];
    } else if (vertex_tets_start[v + 1] > vertex_tets_start[v]) {
      for (std::uint32_t k = vertex_tets_start[v]; k < vertex_tets_start[v + 1]; ++k) {
        ratio += ratio_of_tet[vertex_tets[k]];
      }
      ratio /= static_cast<double>(vertex_tets_start[v + 1] - vertex_tets_start[v]);
    }
    if (!(ratio > 0.0)) {
      continue;
    }
    double nearest2 = kInf;
    for (const std::uint32_t n : fixed) {
      nearest2 = std::min(nearest2, (tets.nodes[n] - rest_surface.vertices[v]).squaredNorm());
    }
    out[v] = ratio / std::max(std::sqrt(nearest2), kFemMinThicknessM);
  }
  return out;
}

}  // namespace

double fem_patch_radius_m(double configured_m, const TriangleMesh& rest_surface) {
  double sum_m = 0.0;
  std::size_t edges = 0;
  for (const auto& tri : rest_surface.triangles) {
    for (std::size_t k = 0; k < 3; ++k) {
      sum_m += (rest_surface.vertices[tri[k]] - rest_surface.vertices[tri[(k + 1) % 3]]).norm();
      ++edges;
    }
  }
  const double mean_edge_m = edges > 0 ? sum_m / static_cast<double>(edges) : 0.0;
  return std::max(configured_m, kFemPatchEdges * mean_edge_m);
}

FemCoupling::FemCoupling(const WorldModel& model) {
  const WorldDescription& d = model.description();
  passivity_damping_factor_ = d.passivity_damping_factor;
  tool_count_ = std::min<std::size_t>(d.tools.size(), kMaxTools);
  for (std::size_t t = 0; t < tool_count_; ++t) {
    tool_radius_m_[t] = d.tools[t].radius_m;
  }
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    const BodyDescription& bd = d.bodies[b];
    if (bd.kind != BodyKind::kDeformable || bd.deformation != BodyDeformation::kFem) {
      continue;
    }
    if (!bd.fem) {
      throw Error("body '" + bd.name + "'", "a FEM body needs its FEM description");
    }
    if (bodies_.size() >= kMaxFemBodies) {
      throw Error("body '" + bd.name + "'",
                  "more than " + std::to_string(kMaxFemBodies) + " FEM bodies in one world");
    }
    if (bd.segments.size() != 1) {
      throw Error("body '" + bd.name + "'", "a FEM body has exactly one segment (its surface)");
    }
    const FemBodyDescription& fd = *bd.fem;
    if (!bodies_.empty() && fd.options.dt_s != bodies_.front()->description->options.dt_s) {
      // One schedule for every FEM body: they are stepped together, one update after another.
      throw Error(fd.source, "dt_s " + std::to_string(fd.options.dt_s) +
                                 " differs from the first FEM body's " +
                                 std::to_string(bodies_.front()->description->options.dt_s) +
                                 ": every FEM body of a world steps at the same rate");
    }
    auto body = std::make_unique<Body>();
    body->world_body = b;
    body->flat_segment = model.flat_segment(BodyIndex{b}, LocalSegment{0}).index();
    body->X_world_body = bd.X_world_body;
    body->X_body_world = bd.X_world_body.inverse();
    body->description = &fd;
    body->fem = std::make_unique<FemBody>(fd.tets, fd.materials, fem_fixed_nodes(model, bd, fd),
                                          fd.options, fd.source);
    body->surface = bd.segments.front().mesh;
    if (fd.embedded_surface) {
      body->embedding = embed_points(fd.tets, body->surface.vertices);
    } else {
      // The segment's mesh is the tets' boundary: match its vertices to the boundary's nodes.
      const TetBoundary boundary = tet_boundary(fd.tets);
      if (boundary.surface.vertices.size() != body->surface.vertices.size()) {
        throw Error(fd.source, "the body's surface is not its tets' boundary (" +
                                   std::to_string(body->surface.vertices.size()) + " vertices, " +
                                   std::to_string(boundary.surface.vertices.size()) +
                                   " on the boundary)");
      }
      body->node_of_vertex = boundary.node_of_vertex;
    }
    body->rest_surface = body->surface;
    body->rest_surface.compute_vertex_normals();
    body->rest_bvh = std::make_unique<MeshBvh>(body->rest_surface);
    body->patch_radius_m = fem_patch_radius_m(fd.contact_patch_radius_m, body->rest_surface);
    body->margin_m = fd.contact_margin_m;
    for (auto& p : body->patch) {
      p.reserve(256);
    }
    for (Vec3& shift : body->patch_shift) {
      shift.setZero();
    }
    body->loads.reserve(std::size_t{256} * static_cast<std::size_t>(kMaxTools));
    // Which tets touch each boundary vertex (its stress is their mean), as a flat list.
    const std::size_t nv = body->surface.vertices.size();
    if (body->embedding.empty()) {
      std::vector<std::int64_t> vertex_of_node(fd.tets.nodes.size(), -1);
      for (std::size_t v = 0; v < nv; ++v) {
        vertex_of_node[body->node_of_vertex[v]] = static_cast<std::int64_t>(v);
      }
      std::vector<std::vector<std::uint32_t>> lists(nv);
      for (std::size_t t = 0; t < fd.tets.tets.size(); ++t) {
        for (const std::uint32_t n : fd.tets.tets[t]) {
          if (vertex_of_node[n] >= 0) {
            lists[static_cast<std::size_t>(vertex_of_node[n])].push_back(
                static_cast<std::uint32_t>(t));
          }
        }
      }
      body->vertex_tets_start.push_back(0);
      for (const auto& l : lists) {
        body->vertex_tets.insert(body->vertex_tets.end(), l.begin(), l.end());
        body->vertex_tets_start.push_back(static_cast<std::uint32_t>(body->vertex_tets.size()));
      }
    }
    body->stiffening_per_m =
        fem_stiffening_per_m(fd, *body->fem, body->rest_surface, body->embedding,
                             body->vertex_tets_start, body->vertex_tets);
    for (Vec3& n : body->patch_normal) {
      n.setZero();
    }
    body->tet_von_mises_pa.assign(fd.tets.tets.size(), 0.0);
    body->frame.vertices = body->surface.vertices;
    body->frame.von_mises_pa.assign(nv, 0.0f);
    published_surfaces_.push_back(std::make_unique<TripleBuffer<FemSurfaceFrame>>(body->frame));
    bodies_.push_back(std::move(body));
  }
}

const FemSurfaceFrame* FemCoupling::take_published_surface(std::size_t fem_index) {
  TripleBuffer<FemSurfaceFrame>& buffer = *published_surfaces_.at(fem_index);
  return buffer.update() ? &buffer.read_slot() : nullptr;
}

const std::vector<float>& FemCoupling::surface_von_mises_pa(std::size_t fem_index) const {
  return bodies_.at(fem_index)->frame.von_mises_pa;
}

FemCoupling::~FemCoupling() = default;

std::size_t FemCoupling::world_body(std::size_t fem_index) const {
  return bodies_.at(fem_index)->world_body;
}

const TriangleMesh& FemCoupling::surface(std::size_t fem_index) const {
  return bodies_.at(fem_index)->surface;
}

const std::vector<FemNodeWeight>& FemCoupling::contact_patch(std::size_t fem_index,
                                                             std::size_t tool) const {
  return bodies_.at(fem_index)->patch.at(tool);
}

const FemBody& FemCoupling::body(std::size_t fem_index) const {
  return *bodies_.at(fem_index)->fem;
}

FemBody& FemCoupling::body(std::size_t fem_index) {
  return *bodies_.at(fem_index)->fem;
}

// haptic path
void FemCoupling::adopt(WorldState& state, double dt_s) noexcept {
  if (period_steps_.load(std::memory_order_relaxed) == 0 && dt_s > 0.0 && !bodies_.empty()) {
    const double fem_dt = bodies_.front()->description->options.dt_s;
    const double ratio = std::round(fem_dt / dt_s);
    period_steps_.store(
        ratio >= 1.0 && std::isfinite(ratio) ? static_cast<std::uint64_t>(ratio) : 1U,
        std::memory_order_release);
  }
  if (!pending_known_) {
    pending_known_ = updates_.update();
  }
  if (!pending_known_) {
    return;
  }
  const FemUpdate& u = updates_.read_slot();
  if (u.epoch != epoch_.load(std::memory_order_relaxed)) {
    pending_known_ = false;  // from before a reset
    return;
  }
  const std::uint64_t due = u.launch_step + period_steps_.load(std::memory_order_relaxed);
  if (state.step_index < due) {
    return;  // a fixed latency: adopted exactly one FEM period after its launch
  }
  for (std::size_t t = 0; t < tool_count_; ++t) {
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      FemToolContact& fc = state.fem_contacts[t * kMaxFemBodies + b];
      fc.previous_model = fc.model;
      fc.model = u.models[t * kMaxFemBodies + b];
      fc.adopted_this_step = true;
    }
  }
  pending_known_ = false;
  last_adopted_launch_ = u.launch_step;
  ++adopted_;
  if (state.step_index > due) {
    ++late_adopted_;
  }
}

// haptic path
void FemCoupling::capture(const WorldModel& model, const WorldState& state) noexcept {
  const std::uint64_t period = period_steps_.load(std::memory_order_relaxed);
  if (period == 0 || state.step_index % period != 0) {
    return;
  }
  FemLaunch& l = launches_.write_slot();
  l.step_index = state.step_index;
  l.epoch = epoch_.load(std::memory_order_relaxed);
  l.time_s = state.time_s;
  for (std::size_t t = 0; t < tool_count_; ++t) {
    l.p_world[t] = state.tools[t].p_world;
    l.v_world[t] = state.tools[t].v_world;
    l.usable[t] = state.tools[t].input_usable;
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      l.push_world_n[t * kMaxFemBodies + b] =
          state.fem_contacts[t * kMaxFemBodies + b].push_world_n;
    }
  }
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const ContactMaterial& m = state.materials[model.segments()[bodies_[b]->flat_segment].material];
    l.contact_stiffness_n_per_m[b] = m.stiffness_n_per_m;
    l.max_force_n[b] = m.max_force_n;
  }
  launches_.publish();
  last_launch_step_ = state.step_index;
}

bool FemCoupling::run_pending() {
  if (!launches_.update()) {
    return false;
  }
  const FemLaunch& launch = launches_.read_slot();
  if (launch.step_index == 0 || launch.epoch != epoch_.load(std::memory_order_acquire) ||
      launch.step_index == last_run_launch_) {
    return false;
  }
  if (last_run_launch_ != 0) {
    const std::uint64_t period = std::max<std::uint64_t>(1, period_steps());
    stats_.skipped_launches += (launch.step_index - last_run_launch_) / period - 1;
  }
  last_run_launch_ = launch.step_index;
  const Stopwatch watch;
  FemUpdate& out = updates_.write_slot();
  out.launch_step = launch.step_index;
  out.epoch = launch.epoch;
  out.sequence = ++sequence_;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    update_body(b, launch, out);
    // Same sizes every time: the copy reuses the slot's storage.
    Body& body = *bodies_[b];
    body.fem->von_mises_pa(body.tet_von_mises_pa);
    body.frame.vertices = body.surface.vertices;
    for (std::size_t v = 0; v < body.frame.von_mises_pa.size(); ++v) {
      double vm = 0.0;
      if (body.embedding.empty()) {
        const std::uint32_t first = body.vertex_tets_start[v];
        const std::uint32_t end = body.vertex_tets_start[v + 1];
        for (std::uint32_t k = first; k < end; ++k) {
          vm += body.tet_von_mises_pa[body.vertex_tets[k]];
        }
        vm = end > first ? vm / (end - first) : 0.0;
      } else {
        vm = body.tet_von_mises_pa[body.embedding[v].tet];
      }
      body.frame.von_mises_pa[v] = static_cast<float>(vm);
    }
    published_surfaces_[b]->write_slot() = body.frame;
    published_surfaces_[b]->publish();
  }
  updates_.publish();
  surface_version_.fetch_add(1, std::memory_order_acq_rel);
  ++stats_.updates;
  stats_.update_ms.push_back(watch.elapsed_ms());
  return true;
}

void FemCoupling::update_body(std::size_t b, const FemLaunch& launch, FemUpdate& out) {
  Body& body = *bodies_[b];
  FemBody& fem = *body.fem;
  const TetMesh& tets = fem.rest_mesh();
  // 1. The tissue takes the force each tool felt (what the device rendered), on its patch.
  body.loads.clear();
  for (std::size_t t = 0; t < tool_count_; ++t) {
    const Vec3& push = launch.push_world_n[t * kMaxFemBodies + b];
    if (body.patch[t].empty() || !(push.squaredNorm() > 0.0)) {
      continue;
    }
    // Strain stiffening: the linear tissue takes the force over the secant factor
    // s = 1 + κ·δ at its patch's indentation δ, so it indents as F = k₁·δ·(1 + κ·δ) would
    // (κ = E₁/(E₀·h): Zheng & Mak's quadratic); 1 where the tissue is linear.
    const double indentation_m = std::max(0.0, -body.patch_normal[t].dot(body.patch_shift[t]));
    const double secant_factor = 1.0 + body.patch_stiffening_per_m[t] * indentation_m;
    const Vec3 f_tissue_body = body.X_body_world.linear() * (-push) / secant_factor;
    for (const FemNodeWeight& w : body.patch[t]) {
      body.loads.push_back({w.node, w.weight * f_tissue_body});
    }
  }
  fem.set_loads(body.loads);
  const FemStepStats st = fem.step();
  out.solve_ms[b] = st.solve_ms;
  out.cg_iterations[b] = st.cg_iterations;
  // 2. The surface follows the volume.
  const std::vector<Vec3>& x = fem.positions();
  double max_u = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    max_u = std::max(max_u, (x[i] - tets.nodes[i]).norm());
  }
  out.max_displacement_m[b] = max_u;
  max_displacement_m_[b].store(max_u, std::memory_order_relaxed);
  if (body.embedding.empty()) {
    for (std::size_t v = 0; v < body.surface.vertices.size(); ++v) {
      body.surface.vertices[v] = x[body.node_of_vertex[v]];
    }
  } else {
    for (std::size_t v = 0; v < body.surface.vertices.size(); ++v) {
      body.surface.vertices[v] = embedded_position(tets, x, body.embedding[v]);
    }
  }
  body.surface.compute_vertex_normals();
  // 3. Per tool, the local contact model about where the tool is now.
  for (std::size_t t = 0; t < tool_count_; ++t) {
    LocalContactModel& m = out.models[t * kMaxFemBodies + b];
    m = LocalContactModel{};
    std::vector<FemNodeWeight>& patch = body.patch[t];
    patch.clear();
    Body::Secant secant = body.secant[t];  // kept only while the tool stays in contact
    body.secant[t] = Body::Secant{};
    Body::QueryShift query = body.query[t];  // likewise
    body.query[t] = Body::QueryShift{};
    if (!launch.usable[t]) {
      continue;
    }
    const double radius = tool_radius_m_[t];
    const Vec3 p_body = body.X_body_world * launch.p_world[t];
    // The contact is a material point of the tissue: the rest surface's closest point to the tool
    // less the displacement its patch had (a tool that pushed the surface in finds the same
    // point, not the rim of its own dent). Its gap is measured along the patch's normal from
    // where the patch is now: exactly the series law the model linearises,
    // F = k_c·(d − n·H·u), whatever the dent's shape.
    // One step of the search towards the patch's displacement; a step that reverses the last one
    // (the search overshot) makes the following steps shorter.
    const Vec3 step = body.patch_shift[t] - query.shift;
    if (step.norm() > kFemQueryReversalM && step.dot(query.last_step) < 0.0) {
      query.relaxation = std::max(kFemQueryMinRelaxation, 0.5 * query.relaxation);
    }
    query.shift =
        query.relaxation < 1.0 ? Vec3(query.shift + query.relaxation * step) : body.patch_shift[t];
    query.last_step = step;
    const SurfacePoint sp = body.rest_bvh->closest_point(p_body - query.shift, &body.hints[t]);
    body.patch_shift[t].setZero();
    if (!sp.found() || !std::isfinite(sp.signed_distance) ||
        sp.triangle >= body.surface.triangles.size()) {
      continue;
    }
    // The contact patch: surface vertices within the patch radius of the contact point (at
    // rest), weighted by a smooth bump (their sum is one).
    const double r_patch = std::max(body.patch_radius_m, radius);
    double sum = 0.0;
    double stiffening_per_m = 0.0;  // the patch's, weighted as its load
    // The load's direction: the patch's rest normal (in the body's frame, so it turns with the
    // body), as small-strain contact theory (Hertz, Boussinesq) takes it. Not the dent's deformed
    // normal: that fed the dent's own slope back into the load, and a probe held still 6-8 mm
    // deep then wandered or rang sideways (0.4 N drifting, ±1 N ringing on the bench block).
    Vec3 normal = Vec3::Zero();
    for (std::size_t v = 0; v < body.rest_surface.vertices.size(); ++v) {
      const double d2 = (body.rest_surface.vertices[v] - sp.point).squaredNorm();
      if (d2 < r_patch * r_patch) {
        const double w = 1.0 - d2 / (r_patch * r_patch);
        sum += w;
        stiffening_per_m += w * body.stiffening_per_m[v];
        normal += w * body.rest_surface.vertex_normals[v];
        if (body.embedding.empty()) {
          patch.push_back({body.node_of_vertex[v], w});
        } else {
          const TetEmbedding& e = body.embedding[v];
          for (int k = 0; k < 4; ++k) {
            patch.push_back({tets.tets[e.tet][static_cast<std::size_t>(k)], w * e.barycentric[k]});
          }
        }
      }
    }
    if (!(sum > 0.0)) {
      // No vertex that close (a coarse surface): the closest triangle's corners.
      for (std::uint32_t c : body.rest_surface.triangles[sp.triangle]) {
        const double w = 1.0 / 3.0;
        sum += w;
        stiffening_per_m += w * body.stiffening_per_m[c];
        if (body.embedding.empty()) {
          patch.push_back({body.node_of_vertex[c], w});
        } else {
          const TetEmbedding& e = body.embedding[c];
          for (int k = 0; k < 4; ++k) {
            patch.push_back({tets.tets[e.tet][static_cast<std::size_t>(k)], w * e.barycentric[k]});
          }
        }
      }
    }
    Vec3 shift = Vec3::Zero();
    for (FemNodeWeight& w : patch) {
      w.weight /= sum;
      shift += w.weight * (x[w.node] - tets.nodes[w.node]);
    }
    normal = normal.squaredNorm() > 0.0 ? Vec3(normal.normalized())
                                        : body.rest_surface.face_normal(sp.triangle);
    if (!(normal.squaredNorm() > 0.0)) {
      normal = sp.normal;
    }
    const double penetration_m = radius - normal.dot(p_body - (sp.point + shift));
    if (penetration_m < -body.margin_m) {
      patch.clear();  // free space: no model, no load next time
      continue;
    }
    body.patch_shift[t] = shift;
    body.query[t] = query;
    const Vec3 n_world = body.X_world_body.linear() * normal;
    const double rendered_n =
        std::max(0.0, launch.push_world_n[t * kMaxFemBodies + b].dot(n_world));
    // The tissue's own compliance at the patch along the normal, in series with the contact.
    // compliance_along is the rest stiffness turned into the nodes' frames; a corotational body
    // squeezed by a third of its depth answers a change of load up to several times softer than
    // that. Quasi-static, each update is an equilibrium, and f0's correction is a Newton step on
    // the contact's force with that compliance as slope: at more than twice too stiff a slope
    // the held force flipped between two values every update (1.4 and 2.5 N, 7 mm into the
    // bench's block). The secant of the last two updates (load and patch displacement along the
    // normal) measures the softening; it is kept between 1 and kFemMaxSoftening and taken only
    // from a load change large enough to measure it. Backward Euler: its lagging surface would
    // make the secant measure inertia, and it damps the loop itself.
    Body::Compliance& cached = body.compliance[t];
    const bool reuse = fem.options().elasticity == FemElasticity::kLinear && cached.valid &&
                       (cached.point - sp.point).norm() < kFemComplianceReuseM &&
                       cached.normal.dot(normal) > kFemComplianceReuseCos;
    if (!reuse) {
      cached = Body::Compliance{true, sp.point, normal, fem.compliance_along(patch, normal)};
    }
    double compliance_m_per_n = cached.m_per_n;
    if (fem.options().integration == FemIntegration::kQuasiStatic && compliance_m_per_n > 0.0 &&
        std::isfinite(compliance_m_per_n)) {
      Body::Secant& sc = secant;
      const double normal_shift_m = normal.dot(shift);
      const double d_load_n = rendered_n - sc.load_n;
      if (sc.valid && std::abs(d_load_n) >
                          std::max(kFemSecantMinLoadStepN,
                                   kFemSecantMinLoadFraction * std::max(rendered_n, sc.load_n))) {
        const double measured_m_per_n = -(normal_shift_m - sc.normal_shift_m) / d_load_n;
        sc.softening =
            std::isfinite(measured_m_per_n)
                ? std::clamp(measured_m_per_n / compliance_m_per_n, 1.0, kFemMaxSoftening)
                : sc.softening;
      }
      sc.valid = true;
      sc.load_n = rendered_n;
      sc.normal_shift_m = normal_shift_m;
      compliance_m_per_n *= sc.softening;
      body.secant[t] = sc;
    }
    // Strain stiffening: the slope of F = k₁·δ·(1 + κ·δ) at the patch's indentation.
    stiffening_per_m /= sum;
    compliance_m_per_n /= 1.0 + 2.0 * stiffening_per_m * std::max(0.0, -normal.dot(shift));
    body.patch_stiffening_per_m[t] = stiffening_per_m;
    body.patch_normal[t] = normal;
    const double k_tissue = compliance_m_per_n > 0.0 && std::isfinite(compliance_m_per_n)
                                ? 1.0 / compliance_m_per_n
                                : kInf;
    const double k_contact = launch.contact_stiffness_n_per_m[b];
    const double k_series = series_stiffness_n_per_m(k_contact, k_tissue);
    m.x0_world_m = launch.p_world[t];
    m.v0_world_m_per_s = launch.v_world[t];
    m.f0_world_n = tissue_coupled_force_n(rendered_n, penetration_m, k_contact, k_series) * n_world;
    m.stiffness_n_per_m = k_series * n_world * n_world.transpose();
    // A dynamic tissue's motion reaches the hand sampled at the FEM's period T (f0 is refreshed
    // once a period): Colgate's floor for that sampling, factor·k·T, which the stage honours
    // with the material's and its own factor·k·dt. Quasi-static, f0 is the equilibrium and the
    // spring between updates exact: no floor of its own (the passivity sweep's rows: omega3 at
    // 1.5x its rating generated 0.24 J with backward Euler below it, none quasi-static).
    const double b_sample = fem.options().integration == FemIntegration::kBackwardEuler
                                ? passivity_damping_floor_n_s_per_m(passivity_damping_factor_,
                                                                    k_series, fem.options().dt_s)
                                : 0.0;
    m.damping_n_s_per_m = b_sample * n_world * n_world.transpose();
    m.normal_world = n_world;
    m.validity_radius_m = body.margin_m + radius;
    m.max_normal_force_n = launch.max_force_n[b];
    m.sim_time_s = launch.time_s;
    m.sequence = sequence_;
    m.device_sequence = launch.step_index;
    m.valid = k_series > 0.0;
  }
}

void FemCoupling::reset() {
  for (auto& body : bodies_) {
    body->fem->reset();
    body->surface.vertices.clear();
    for (auto& p : body->patch) {
      p.clear();
    }
    body->hints = {};
    body->query = {};
    for (Vec3& shift : body->patch_shift) {
      shift.setZero();
    }
    for (Vec3& n : body->patch_normal) {
      n.setZero();
    }
    body->patch_stiffening_per_m = {};
    body->compliance = {};
    body->secant = {};
  }
  // The rest surfaces again.
  for (auto& body : bodies_) {
    const std::vector<Vec3>& x = body->fem->positions();
    body->surface.vertices.resize(body->embedding.empty() ? body->node_of_vertex.size()
                                                          : body->embedding.size());
    for (std::size_t v = 0; v < body->surface.vertices.size(); ++v) {
      body->surface.vertices[v] =
          body->embedding.empty()
              ? x[body->node_of_vertex[v]]
              : embedded_position(body->fem->rest_mesh(), x, body->embedding[v]);
    }
  }
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    Body& body = *bodies_[b];
    body.frame.vertices = body.surface.vertices;
    std::fill(body.frame.von_mises_pa.begin(), body.frame.von_mises_pa.end(), 0.0f);
    published_surfaces_[b]->write_slot() = body.frame;
    published_surfaces_[b]->publish();
  }
  epoch_.fetch_add(1, std::memory_order_acq_rel);
  for (auto& u : max_displacement_m_) {
    u.store(0.0, std::memory_order_relaxed);
  }
  pending_known_ = false;
  last_run_launch_ = 0;
  last_launch_step_ = 0;
  last_adopted_launch_ = 0;
}

}  // namespace hapsim
