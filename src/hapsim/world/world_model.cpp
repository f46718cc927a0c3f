#include "hapsim/world/world_model.h"

#include "hapsim/collision/csg_query.h"
#include "hapsim/collision/knee_index.h"
#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/collision/sphere_tree.h"
#include "hapsim/core/device_io.h"
#include "hapsim/core/error.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/deform/sheet_profile.h"
#include "hapsim/force/god_object.h"
#include "hapsim/world/knee_method_query.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace hapsim {

namespace {

// A CSG segment (and an exact sphere) always answers from its solid's signed distance (exact, and
// cheaper than any mesh structure), whatever the body's method: the method names how a *mesh* is
// searched, and the polygonised mesh only approximates the solid (edges bevelled by about a cell).
std::unique_ptr<ProximityQuery> make_query(ContactMethod method, const SegmentDescription& segment,
                                           ContactResponse response,
                                           std::optional<ApproximationError>* knee_error) {
  if (segment.csg) {
    return std::make_unique<CsgQuery>(*segment.csg, segment.mesh);
  }
  if (segment.sphere) {
    // Exactly a sphere: its signed distance answers exactly (the mesh only tessellates it).
    const Iso3 X_body_sphere(Eigen::Translation3d(segment.sphere->center_body));
    return std::make_unique<CsgQuery>(
        CsgSolid::sphere(segment.sphere->radius_m).transformed(X_body_sphere), segment.mesh);
  }
  const TriangleMesh& mesh = segment.mesh;
  switch (method) {
    case ContactMethod::kSphereTree:
      return std::make_unique<SphereTree>(mesh);
    case ContactMethod::kKnee: {
      KneeMethodQuery knee = make_knee_method_query(mesh, response);
      if (knee.poor) {
        *knee_error = knee.error;
      }
      return std::move(knee.query);
    }
    case ContactMethod::kExact:
      break;
  }
  return std::make_unique<MeshBvh>(mesh);
}

// A dynamic body needs a usable mass and inertia; its segments answer by penalty (a god-object's
// proxy assumes a surface that stays put within the cycle).
void check_dynamic(const WorldDescription& d, const BodyDescription& body) {
  const std::string where = "body '" + body.name + "'";
  const RigidBodyDescription& r = body.rigid;
  if (!(r.mass_kg > 0.0) || !std::isfinite(r.mass_kg) || !r.com_body.allFinite() ||
      !r.v_world.allFinite() || !r.w_world.allFinite()) {
    throw Error(where, "a dynamic body needs a finite mass > 0 kg and finite start velocities");
  }
  const Mat3& I = r.inertia_kg_m2;
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (I + I.transpose()));
  if (!I.allFinite() || !(eig.eigenvalues().minCoeff() > 0.0) ||
      (I - I.transpose()).norm() > 1e-9 * I.norm()) {
    throw Error(where, "a dynamic body's inertia must be symmetric positive definite");
  }
  for (const SegmentDescription& s : body.segments) {
    if (d.materials.at(s.material).response != ContactResponse::kPenalty) {
      throw Error(where + " segment '" + s.name + "'",
                  "a dynamic body's materials must answer by \"penalty\" (a proxy needs a "
                  "surface that stays put within a cycle)");
    }
  }
}

// A sheet is one segment of the sheet's grid, answered by penalty (it moves under its contacts).
void check_sheet(const WorldDescription& d, const BodyDescription& body) {
  const std::string where = "body '" + body.name + "'";
  if (body.segments.size() != 1) {
    throw Error(where, "a sheet has exactly one segment");
  }
  const SegmentDescription& s = body.segments.front();
  const auto n = static_cast<std::size_t>(std::max(body.sheet.nodes_per_side, 0));
  if (s.mesh.vertex_count() != n * n) {
    throw Error(where, "a sheet's mesh must be its " + std::to_string(n) + "x" + std::to_string(n) +
                           " grid (make_sheet)");
  }
  if (d.materials.at(s.material).response != ContactResponse::kPenalty) {
    throw Error(where,
                "a sheet's material must answer by \"penalty\" (the sheet moves under "
                "its contacts)");
  }
}

// How many of a mesh's vertex springs press a sheet together, at most: for each of the mesh's face
// directions, the vertices within a couple of millimetres of its support plane there (they sink
// into the sheet together), each weighted by the sheet's dent under one of them at the others
// (the Gaussian profile over their distance, relative to its centre); the largest row sum over
// them bounds the press's gain (Gershgorin). A sphere touches at one point: 1.
double press_springs(const SegmentDescription& segment, const GaussianSheetProfile& profile) {
  if (segment.sphere) {
    return 1.0;
  }
  constexpr double kTogether_m = 0.002;
  const TriangleMesh& mesh = segment.mesh;
  const double centre = profile.depth_m(0.0, 1.0);
  double most = 1.0;
  std::vector<std::uint32_t> plane;
  for (const auto& t : mesh.triangles) {
    const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                       .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    if (!(n.norm() > 0.0)) {
      continue;
    }
    const Vec3 d = n.normalized();
    double support = -kInf;
    for (const Vec3& v : mesh.vertices) {
      support = std::max(support, v.dot(d));
    }
    plane.clear();
    for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v) {
      if (mesh.vertices[v].dot(d) > support - kTogether_m) {
        plane.push_back(v);
      }
    }
    if (static_cast<double>(plane.size()) <= most) {
      continue;
    }
    for (const std::uint32_t i : plane) {
      double row = 0.0;
      for (const std::uint32_t j : plane) {
        row += profile.depth_m((mesh.vertices[i] - mesh.vertices[j]).norm(), 1.0) / centre;
      }
      most = std::max(most, row);
    }
  }
  return most;
}

void check_tool(const ToolDescription& td) {
  if (!(td.radius_m >= 0.0) || !std::isfinite(td.radius_m) || !td.offset_device.allFinite()) {
    throw Error("tool '" + td.name + "'", "needs a finite radius >= 0 and a finite offset");
  }
  if (td.finger >= kMaxFingers) {
    throw Error("tool '" + td.name + "'",
                "finger must be below " + std::to_string(kMaxFingers) + " (or -1)");
  }
}

}  // namespace

WorldModel::WorldModel(WorldDescription description, WorldOptions options)
    : description_(std::move(description)), options_(options) {
  const Stopwatch watch;
  if (description_.has_hand) {
    hand_ = std::make_unique<HandModel>(description_.hand);
    for (const ToolDescription& t : description_.tools) {
      if (t.finger < 0 || t.finger >= kHandFingers) {
        throw Error("tool '" + t.name + "'",
                    "a glove drives the tools: expected a finger 0 (thumb) .. 4 (little)");
      }
    }
  }
  for (const ToolDescription& t : description_.tools) {
    max_tool_radius_m_ = std::max(max_tool_radius_m_, t.radius_m);
  }
  for (std::size_t b = 0; b < description_.bodies.size(); ++b) {
    const BodyDescription& body = description_.bodies[b];
    body_first_segment_.push_back(FlatSegment{segments_.size()});
    if (body.segments.empty()) {
      throw Error("body '" + body.name + "'", "has no segments");
    }
    std::vector<std::string> exact_proxy_segments;  // knee method asked, exact query given
    std::vector<std::pair<std::string, ApproximationError>> poor_knee_segments;
    std::size_t knee_penalty_segments = 0;
    for (std::size_t s = 0; s < body.segments.size(); ++s) {
      const SegmentDescription& sd = body.segments[s];
      const std::string where = "body '" + body.name + "' segment '" + sd.name + "'";
      if (sd.mesh.empty()) {
        throw Error(where, "has an empty mesh");
      }
      if (sd.material >= description_.materials.size()) {
        throw Error(where, "refers to material " + std::to_string(sd.material) + " of " +
                               std::to_string(description_.materials.size()));
      }
      if (s == 0 && body.kind == BodyKind::kDynamic) {
        check_dynamic(description_, body);
      }
      const bool sheet =
          body.kind == BodyKind::kDeformable && body.deformation == BodyDeformation::kGaussianSheet;
      if (s == 0 && sheet) {
        check_sheet(description_, body);
      }
      const bool fem =
          body.kind == BodyKind::kDeformable && body.deformation == BodyDeformation::kFem;
      if (fem && (!body.fem || body.segments.size() != 1)) {
        throw Error("body '" + body.name + "'",
                    "a FEM body needs its volume and exactly one segment (its surface)");
      }
      if (fem && s == 0) {
        fem_bodies_.push_back(b);
      }
      SegmentModel seg;
      seg.sheet = sheet;
      seg.fem = fem;
      seg.dynamic = body.kind == BodyKind::kDynamic;
      seg.body = b;
      seg.index_in_body = LocalSegment{s};
      seg.description = &sd;
      seg.material = sd.material;
      seg.response = description_.materials[sd.material].response;
      seg.deformable = body.kind == BodyKind::kDeformable && !sheet && !fem;  // vertex deflection
      seg.X_world_body = body.X_world_body;
      seg.X_body_world = body.X_world_body.inverse();
      seg.rest_bounds_body = sd.mesh.bounds();
      if (sheet) {
        // The sheet sinks under its contacts: as deep as its cap, or (uncapped) its side.
        const double deepest =
            std::isfinite(body.sheet.max_depth_m) ? body.sheet.max_depth_m : body.sheet.side_m;
        seg.rest_bounds_body.extend(seg.rest_bounds_body.min() - Vec3(0.0, 0.0, deepest));
      }
      std::optional<ApproximationError> knee_error;
      seg.rest_query = make_query(body.method, sd, seg.response, &knee_error);
      if (knee_error) {
        poor_knee_segments.emplace_back(sd.name, *knee_error);
      }
      knee_penalty_segments += body.method == ContactMethod::kKnee && !sd.csg && !sd.sphere &&
                                       seg.response == ContactResponse::kPenalty
                                   ? 1
                                   : 0;
      if (body.method == ContactMethod::kKnee && !sd.csg && !sd.sphere &&
          seg.response == ContactResponse::kProxy) {
        exact_proxy_segments.push_back(sd.name);
      }
      if (!fem) {
        (seg.response == ContactResponse::kProxy ? proxy_segments_ : penalty_segments_) += 1;
      }
      segments_.push_back(std::move(seg));
    }
    if (!exact_proxy_segments.empty()) {
      std::string names;
      for (const std::string& n : exact_proxy_segments) {
        names += (names.empty() ? "" : ", ") + n;
      }
      notes_.push_back("body '" + body.name + "' (contact_method knee): its " +
                       std::to_string(exact_proxy_segments.size()) +
                       " proxy segment(s) answer with the exact query (" + names +
                       "): the god-object keeps its proxy on a surface only with a continuous "
                       "signed distance, which the knee method's planes are not; its penalty "
                       "segments use the knee method");
    }
    if (!poor_knee_segments.empty()) {
      notes_.push_back(describe_poor_knee_segments(body.name, knee_penalty_segments,
                                                   std::move(poor_knee_segments)));
    }
  }
  for (std::size_t b = 0; b < description_.bodies.size(); ++b) {
    const BodyDescription& body = description_.bodies[b];
    BodyModel bm;
    bm.kind = body.kind;
    bm.first_segment = body_first_segment_[b];
    bm.segment_count = body.segments.size();
    bm.sheet = segments_[bm.first_segment.index()].sheet;
    if (bm.sheet) {
      bm.sheet_compliance_m_per_n = GaussianSheetProfile(body.sheet_profile).depth_m(0.0, 1.0);
    }
    if (body.kind == BodyKind::kDynamic) {
      bm.mass_kg = body.rigid.mass_kg;
      bm.com_body = body.rigid.com_body;
      bm.inertia_body_kg_m2 = body.rigid.inertia_kg_m2;
      bm.inverse_inertia_body = body.rigid.inertia_kg_m2.inverse();
      if (body.segments.size() == 1 && body.segments.front().sphere) {
        bm.sphere = body.segments.front().sphere;
      } else {
        has_dynamic_meshes_ = true;
      }
      bm.dynamic_index = static_cast<std::int32_t>(dynamic_bodies_.size());
      dynamic_bodies_.push_back(b);
      for (std::size_t s = 0; s < bm.segment_count; ++s) {
        dynamic_segments_.push_back(bm.first_segment.index() + s);
      }
    }
    bodies_.push_back(bm);
  }
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    if (bodies_[b].sheet) {
      const GaussianSheetProfile profile(description_.bodies[b].sheet_profile);
      for (const std::size_t dyn : dynamic_segments_) {
        bodies_[b].sheet_press_springs.push_back(
            press_springs(*segments_[dyn].description, profile));
      }
    }
  }
  check_sheet_contacts();
  if (!dynamic_bodies_.empty()) {
    for (SegmentModel& seg : segments_) {
      // A sheet answers body contacts from its field. A CSG solid or exact sphere answers a
      // dynamic sphere exactly without a tree; a dynamic mesh finds the vertices that may touch
      // it through the tree of its polygonised mesh.
      const bool exact = seg.description->csg || seg.description->sphere;
      if (!seg.sheet && (!exact || has_dynamic_meshes_)) {
        seg.body_tree = std::make_unique<SphereTree>(seg.description->mesh);
      }
    }
  }
  // A kinematic body (moved by a controller: a robot's links and pads) has its tree in any world:
  // the controller finds where it enters what it cannot push back with it (a robot's link in the
  // table or the patient, rig/slave_collisions.cpp), dynamic bodies or not.
  for (SegmentModel& seg : segments_) {
    if (!seg.body_tree && !seg.sheet && bodies_[seg.body].kind == BodyKind::kKinematic) {
      seg.body_tree = std::make_unique<SphereTree>(seg.description->mesh);
    }
  }
  if (proxy_segments_ > static_cast<std::size_t>(GodObject::kMaxSurfaces)) {
    throw Error("world '" + description_.name + "'",
                "has " + std::to_string(proxy_segments_) + " proxy segments; at most " +
                    std::to_string(GodObject::kMaxSurfaces) + " are supported");
  }
  for (const ToolDescription& td : description_.tools) {
    check_tool(td);
  }
  if (description_.tools.size() > static_cast<std::size_t>(kMaxTools)) {
    throw Error("world '" + description_.name + "'",
                "has " + std::to_string(description_.tools.size()) + " tools; at most " +
                    std::to_string(kMaxTools) + " are supported");
  }
  if (description_.controller) {
    description_.controller->check(description_);
  }
  build_ms_ = watch.elapsed_ms();
}

WorldModel::~WorldModel() = default;

// A sheet answers contacts from its elastic field, which takes this step's push one step later:
// the push and the field's give settle only while the contact spring is softer than the sheet
// under a contact, k · compliance < 1 (else the press grows from step to step).
// haptic path
bool WorldModel::sheet_presses_settle(std::span<const ContactMaterial> materials,
                                      SheetPress* unsettled) const noexcept {
  const WorldDescription& d = description_;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    if (!bodies_[b].sheet) {
      continue;
    }
    const double compliance_m_per_n = bodies_[b].sheet_compliance_m_per_n;
    const ContactMaterial& own = materials[segments_[bodies_[b].first_segment.index()].material];
    // Each spring that presses the sheet must be softer than the sheet gives way under it, or the
    // press overshoots further each step.
    const auto settles = [&](double k, std::ptrdiff_t presser) {
      if (k * compliance_m_per_n < 1.0) {
        return true;
      }
      if (unsettled != nullptr) {
        *unsettled = SheetPress{b, presser, k, 1.0 / compliance_m_per_n};
      }
      return false;
    };
    if (!d.tools.empty() &&
        !settles(std::min(own.stiffness_n_per_m, options_.max_stiffness_n_per_m), -1)) {
      return false;
    }
    for (std::size_t i = 0; i < dynamic_segments_.size(); ++i) {
      const std::size_t dyn = dynamic_segments_[i];
      const ContactMaterial& presser = materials[segments_[dyn].material];
      // A mesh presses with several springs side by side, the sheet giving way under all.
      const double springs =
          bodies_[b].sheet_press_springs.empty() ? 1.0 : bodies_[b].sheet_press_springs[i];
      if (!settles(springs * combine_materials(presser, own).stiffness_n_per_m,
                   static_cast<std::ptrdiff_t>(segments_[dyn].body))) {
        return false;
      }
    }
  }
  return true;
}

void WorldModel::check_sheet_contacts() const {
  std::vector<ContactMaterial> materials;
  for (const MaterialDescription& m : description_.materials) {
    materials.push_back(m.contact);
  }
  SheetPress press;
  if (sheet_presses_settle(materials, &press)) {
    return;
  }
  const std::string what =
      press.presser < 0
          ? std::string("a tool")
          : "body '" + description_.bodies[static_cast<std::size_t>(press.presser)].name + "'";
  throw Error("body '" + description_.bodies[press.sheet_body].name + "'",
              what + " presses the sheet with " + std::to_string(press.stiffness_n_per_m) +
                  " N/m, not softer than the sheet under a contact (" +
                  std::to_string(press.sheet_stiffness_n_per_m) +
                  " N/m): the press would not settle; soften the material or stiffen the "
                  "sheet (sensitivity_n_per_mm)");
}

std::size_t WorldModel::query_memory_bytes() const {
  std::size_t bytes = 0;
  for (const SegmentModel& seg : segments_) {
    bytes += seg.rest_query->memory_bytes();
    if (seg.body_tree) {
      bytes += seg.body_tree->memory_bytes();
    }
  }
  return bytes;
}

}  // namespace hapsim
