#include "bench/fem_cases.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/core/statistics.h"
#include "hapsim/core/stopwatch.h"
#include "hapsim/deform/fem_body_description.h"
#include "hapsim/force/local_contact_model.h"
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>

namespace hapsim::bench {
namespace {

constexpr double kHapticDtS = 1e-3;
// The palpation's geometry: from 1 mm above the first touch, 6 mm beyond it, 20 mm sideways.
constexpr double kClearanceM = 0.001;
constexpr double kSlideM = 0.020;
// The haptic-step run: down at x = −10 mm at 20 mm/s, then to and fro along x, pressed.
constexpr double kHapticSpeedMPerS = 0.020;
// The bare solver's load: a press on the top's centre, 0 → 1 N → 0 once a second: about the
// palpation's dent (6 mm on the 20k-tet block; 2 N made 13 mm, two thirds of its depth).
constexpr double kPressPeakN = 1.0;
constexpr double kPressPeriodS = 1.0;
// The reference's Newton iteration on the contact force.
constexpr int kReferenceMaxIterations = 40;
constexpr double kReferenceRelaxation = 0.5;
constexpr int kReferenceIterationsAfterFailure = 8;
// The body has settled when a step moves no node by more than this (k_c times it: 3e-4 N).
constexpr double kReferenceSettledM = 1e-7;
constexpr double kReferenceForceSlackN = 0.1;
// A contact that moves this far, or turns this much, in one iteration is running away.
constexpr double kReferenceRunawayM = 1e-3;
constexpr double kReferenceRunawayNormal = 0.2;
constexpr double kReferenceForceTolN = 1e-4;  // the corotational solves' own noise is ~2e-5 N
// A patch moved by 1 µm changes its weights by under 0.05 %; a normal by 1e-4, the force's
// direction by 0.01 %.
constexpr double kReferencePointTolM = 1e-6;
constexpr double kReferenceNormalTol = 1e-4;
// The secant softening: from a load step of at least 1 mN, at most ten times softer.
constexpr double kReferenceSecantMinLoadStepN = 1e-3;
constexpr double kReferenceMaxSoftening = 10.0;

std::uint32_t as_node(std::size_t i) {
  return static_cast<std::uint32_t>(i);
}

// The nodes the block's world fixes: its bottom face (FemBodyDescription::fixed_below_z_m).
constexpr double kFixedBelowZM = 1e-6;

std::vector<std::uint32_t> bottom_nodes(const TetMesh& tets) {
  std::vector<std::uint32_t> fixed;
  for (std::size_t i = 0; i < tets.nodes.size(); ++i) {
    if (tets.nodes[i].z() <= kFixedBelowZM) {
      fixed.push_back(as_node(i));
    }
  }
  return fixed;
}

TetMesh block_tets(const FemBlockSpec& spec) {
  TetMesh tets = make_tet_block(spec.size_m, spec.cells);
  tets.transform(Iso3(Eigen::Translation3d(-0.5 * spec.size_m.x(), -0.5 * spec.size_m.y(), 0.0)));
  return tets;
}

FemOptions block_options(const FemBlockSpec& spec) {
  FemOptions o;
  o.elasticity = spec.elasticity;
  o.integration = spec.integration;
  o.dt_s = spec.dt_s;
  return o;
}

// The coupling's contact (world/fem_coupling.cpp, update_body), restated: the contact is a
// material point of the tissue, the rest surface's closest point to the tool less the patch's
// displacement; the patch is the rest surface's vertices within the patch radius of it, weighted
// 1 − (r/R)² (or the closest triangle's corners when none is that close), weights summing to one;
// the normal is the patch's weighted rest vertex normal; the penetration is measured along it
// from where the patch is now. F = k_c·penetration is the series law the local model linearises.
struct CouplingContact {
  bool found = false;
  Vec3 rest_point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  Vec3 shift = Vec3::Zero();  // the patch's mean displacement
  double penetration_m = 0.0;
};

CouplingContact coupling_contact(const MeshBvh& rest_bvh, const TriangleMesh& rest_surface,
                                 const std::vector<std::uint32_t>& node_of_vertex,
                                 const FemBody& body, const Vec3& p, const Vec3& query_shift,
                                 double tool_radius_m, double patch_radius_m,
                                 std::vector<FemNodeWeight>& patch) {
  CouplingContact c;
  patch.clear();
  const SurfacePoint sp = rest_bvh.closest_point(p - query_shift);
  if (!sp.found() || !std::isfinite(sp.signed_distance) ||
      sp.triangle >= rest_surface.triangles.size()) {
    return c;
  }
  const double r2 = patch_radius_m * patch_radius_m;
  double sum = 0.0;
  Vec3 normal = Vec3::Zero();
  for (std::size_t v = 0; v < rest_surface.vertices.size(); ++v) {
    const double d2 = (rest_surface.vertices[v] - sp.point).squaredNorm();
    if (d2 < r2) {
      const double w = 1.0 - d2 / r2;
      patch.push_back({node_of_vertex[v], w});
      normal += w * rest_surface.vertex_normals[v];
      sum += w;
    }
  }
  if (!(sum > 0.0)) {
    for (const std::uint32_t corner : rest_surface.triangles[sp.triangle]) {
      patch.push_back({node_of_vertex[corner], 1.0 / 3.0});
      sum += 1.0 / 3.0;
    }
  }
  const TetMesh& rest = body.rest_mesh();
  const std::vector<Vec3>& x = body.positions();
  for (FemNodeWeight& w : patch) {
    w.weight /= sum;
    c.shift += w.weight * (x[w.node] - rest.nodes[w.node]);
  }
  normal = normal.squaredNorm() > 0.0 ? Vec3(normal.normalized())
                                      : rest_surface.face_normal(sp.triangle);
  if (!(normal.squaredNorm() > 0.0)) {
    normal = sp.normal;
  }
  c.found = true;
  c.rest_point = sp.point;
  c.normal = normal;
  c.penetration_m = tool_radius_m - normal.dot(p - (sp.point + c.shift));
  return c;
}

// The bare solver's press: the surface vertices within the patch radius of `point` at rest.
void rest_patch(const TriangleMesh& rest_surface, const std::vector<std::uint32_t>& node_of_vertex,
                const Vec3& point, double radius_m, std::vector<FemNodeWeight>& patch) {
  patch.clear();
  double sum = 0.0;
  for (std::size_t v = 0; v < rest_surface.vertices.size(); ++v) {
    const double d2 = (rest_surface.vertices[v] - point).squaredNorm();
    if (d2 < radius_m * radius_m) {
      const double w = 1.0 - d2 / (radius_m * radius_m);
      patch.push_back({node_of_vertex[v], w});
      sum += w;
    }
  }
  for (FemNodeWeight& w : patch) {
    w.weight /= sum;
  }
}

DeviceInput probe_at(const Vec3& p_world, double time_s) {
  DeviceInput in;
  in.time_s = time_s;
  in.p_world = p_world;
  return in;
}

std::string elasticity_name(FemElasticity e) {
  return std::string(to_string(e));
}

}  // namespace

std::array<int, 3> fem_block_cells(const Vec3& size_m, std::size_t target_tets) {
  const double volume = size_m.x() * size_m.y() * size_m.z();
  const double h =
      std::cbrt(6.0 * volume / static_cast<double>(std::max<std::size_t>(target_tets, 6)));
  std::array<int, 3> cells{};
  for (int a = 0; a < 3; ++a) {
    cells[static_cast<std::size_t>(a)] = std::max(1, static_cast<int>(std::lround(size_m[a] / h)));
  }
  return cells;
}

WorldDescription fem_block_world(const FemBlockSpec& spec) {
  WorldDescription w;
  w.name = "fem-bench-block";
  MaterialDescription m;
  m.name = "soft_block";
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = spec.contact_stiffness_n_per_m;
  m.contact.damping_n_s_per_m = spec.contact_damping_n_s_per_m;
  m.contact.max_force_n = spec.max_force_n;
  m.contact.max_penetration_m = 0.02;
  w.materials.push_back(m);
  auto fem = std::make_shared<FemBodyDescription>();
  fem->tets = block_tets(spec);
  fem->materials = {{0, spec.material}};
  fem->options = block_options(spec);
  fem->fixed_below_z_m = kFixedBelowZM;
  fem->contact_patch_radius_m = spec.patch_radius_m;
  fem->source = "fem bench block";
  BodyDescription b;
  b.name = "block";
  b.kind = BodyKind::kDeformable;
  b.deformation = BodyDeformation::kFem;
  SegmentDescription s;
  s.name = "block";
  s.material = 0;
  s.mesh = tet_boundary(fem->tets).surface;
  b.segments.push_back(std::move(s));
  b.fem = fem;
  w.bodies.push_back(std::move(b));
  w.tools.push_back(ToolDescription{"tip", spec.tool_radius_m, Vec3::Zero(), -1});
  return w;
}

// --- the full solve ------------------------------------------------------------------------------

struct FemContactReference::Impl {
  double k_c = 0.0;
  double tool_radius_m = 0.0;
  double patch_radius_m = 0.0;
  std::unique_ptr<FemBody> body;
  TriangleMesh rest_surface;  // with its vertex normals: the load's direction
  std::vector<std::uint32_t> node_of_vertex;
  std::unique_ptr<MeshBvh> rest_bvh;
  // The load on the body now (solved): its force along its normal on its patch, and the patch's
  // displacement the next contact query starts from (as the coupling keeps it per tool).
  double applied_n = 0.0;
  Vec3 applied_normal = Vec3::UnitZ();
  Vec3 applied_point = Vec3::Zero();
  Vec3 query_shift = Vec3::Zero();
  std::vector<FemNodeWeight> patch;
  std::vector<FemNodeForce> loads;
  std::vector<Vec3> saved_x;
  std::vector<Vec3> before_x;
  std::vector<FemNodeForce> saved_loads;
  // The secant softening (see force_at): the last iterate's load and displacement along the
  // normal, and how much softer than compliance_along the body answered.
  bool secant_valid = false;
  double secant_load_n = 0.0;
  double secant_shift_m = 0.0;
  double softening = 1.0;
  double settled_m = 0.0;    // the largest node move of the last step
  bool last_failed = false;  // the previous point had no equilibrium: fail this one fast
};

FemContactReference::FemContactReference(const FemBlockSpec& spec)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  FemBlockSpec quasi_static = spec;
  quasi_static.integration = FemIntegration::kQuasiStatic;
  m.k_c = spec.contact_stiffness_n_per_m;
  m.tool_radius_m = spec.tool_radius_m;
  TetMesh tets = block_tets(spec);
  const TetBoundary boundary = tet_boundary(tets);
  m.rest_surface = boundary.surface;
  m.rest_surface.compute_vertex_normals();
  m.patch_radius_m =
      std::max(fem_patch_radius_m(spec.patch_radius_m, m.rest_surface), spec.tool_radius_m);
  m.node_of_vertex = boundary.node_of_vertex;
  const std::vector<std::uint32_t> fixed = bottom_nodes(tets);
  m.body = std::make_unique<FemBody>(
      std::move(tets), std::vector<FemRegionMaterial>{FemRegionMaterial{0, spec.material}}, fixed,
      block_options(quasi_static), "fem bench reference");
  m.rest_bvh = std::make_unique<MeshBvh>(m.rest_surface);
}

FemContactReference::~FemContactReference() = default;

std::optional<Vec3> FemContactReference::force_at(const Vec3& p_m) {
  Impl& m = *impl_;
  // Where the iteration starts: the last equilibrium, restored when this point has none.
  m.saved_x = m.body->positions();
  m.saved_loads = m.loads;
  const double saved_n = m.applied_n;
  const Vec3 saved_normal = m.applied_normal;
  const Vec3 saved_point = m.applied_point;
  const Vec3 saved_shift = m.query_shift;
  // No equilibrium pushes harder than the contact spring compressed by the tool's overlap with
  // the rest surface (the surface only gives way), with a margin for the Poisson bulge.
  const SurfacePoint rest = m.rest_bvh->closest_point(p_m);
  const double bound_n =
      1.5 * m.k_c * std::max(0.0, m.tool_radius_m - rest.signed_distance) + kReferenceForceSlackN;
  // Newton on g(F) = F − k_c·max(0, penetration(F)), slope 1 + k_c·c with c the patch's
  // condensed compliance along the normal (the coupling's own update is this step, one per FEM
  // period); converged when g is below the tolerance, the contact point and normal the load went
  // on (hence the patch and the load's direction) no longer move, and the body has settled.
  const int iterations = m.last_failed ? kReferenceIterationsAfterFailure : kReferenceMaxIterations;
  for (int it = 1; it <= iterations; ++it) {
    const CouplingContact c =
        coupling_contact(*m.rest_bvh, m.rest_surface, m.node_of_vertex, *m.body, p_m, m.query_shift,
                         m.tool_radius_m, m.patch_radius_m, m.patch);
    if (!c.found) {
      break;
    }
    const double g = m.applied_n - m.k_c * std::max(0.0, c.penetration_m);
    const double moved_m = (c.rest_point - m.applied_point).norm();
    const double turned = (c.normal - m.applied_normal).norm();
    if ((m.applied_n == 0.0 || (moved_m <= kReferencePointTolM && turned <= kReferenceNormalTol)) &&
        std::abs(g) <= kReferenceForceTolN && m.settled_m <= kReferenceSettledM) {
      max_iterations = std::max(max_iterations, it);
      m.last_failed = false;
      return m.applied_n * m.applied_normal;
    }
    if (it > 2 && m.applied_n > 0.0 &&
        (moved_m > kReferenceRunawayM || turned > kReferenceRunawayNormal)) {
      break;  // the contact runs away: a point 0.1 mm on from an equilibrium moves it far less
    }
    // The patch's place (through the shift the next query starts from) and the load's direction
    // move half way to the new ones: the plain iteration rings (the patch and its normal swing
    // to and fro, decaying slowly), the halved one does not; its fixed point is the same.
    const bool loaded = m.applied_n > 0.0;
    m.query_shift =
        loaded ? Vec3(m.query_shift + kReferenceRelaxation * (c.shift - m.query_shift)) : c.shift;
    const Vec3 normal =
        loaded ? Vec3((m.applied_normal + kReferenceRelaxation * (c.normal - m.applied_normal))
                          .normalized())
               : c.normal;
    double compliance = m.body->compliance_along(m.patch, normal);
    // A corotational body squeezed deep answers softer than compliance_along: the secant of the
    // last two iterates (load against the patch's displacement along the normal), as the
    // coupling measures it, kept at least as soft as compliance_along. Without it the iteration
    // overshot and found no equilibrium beyond 4-5 mm of the palpation.
    const double normal_shift_m = normal.dot(c.shift);
    const double d_load_n = m.applied_n - m.secant_load_n;
    if (m.secant_valid && std::abs(d_load_n) > kReferenceSecantMinLoadStepN && compliance > 0.0) {
      const double measured = -(normal_shift_m - m.secant_shift_m) / d_load_n;
      if (std::isfinite(measured)) {
        m.softening = std::clamp(measured / compliance, 1.0, kReferenceMaxSoftening);
      }
    }
    m.secant_valid = true;
    m.secant_load_n = m.applied_n;
    m.secant_shift_m = normal_shift_m;
    compliance *= m.softening;
    // Out of contact g = F: its slope is 1 (the next iterate lets go); in contact 1 + k_c·c.
    const double slope = c.penetration_m > 0.0 ? 1.0 + m.k_c * std::max(0.0, compliance) : 1.0;
    const double next_n = std::max(0.0, m.applied_n - g / slope);
    if (!std::isfinite(next_n) || next_n > bound_n) {
      break;
    }
    m.loads.clear();
    for (const FemNodeWeight& w : m.patch) {
      m.loads.push_back({w.node, -next_n * w.weight * normal});
    }
    m.body->set_loads(m.loads);
    // One quasi-static step, as the coupling's update takes: exact for the linear model, a few
    // rotation updates for the corotational one (converged over the iterations: settled_m).
    m.before_x = m.body->positions();
    const FemStepStats stats = m.body->step();
    ++solves;
    m.settled_m = 0.0;
    const std::vector<Vec3>& x = m.body->positions();
    for (std::size_t i = 0; i < x.size(); ++i) {
      m.settled_m = std::max(m.settled_m, (x[i] - m.before_x[i]).norm());
    }
    m.applied_n = next_n;
    m.applied_normal = normal;
    m.applied_point = c.rest_point;
    if (!stats.converged) {
      break;
    }
  }
  ++unconverged;
  m.last_failed = true;
  m.settled_m = 0.0;
  m.loads = m.saved_loads;
  m.body->set_loads(m.loads);
  m.body->set_state(m.saved_x);
  m.applied_n = saved_n;
  m.applied_normal = saved_normal;
  m.applied_point = saved_point;
  m.query_shift = saved_shift;
  m.secant_valid = false;  // its last pair was of the state just undone
  return std::nullopt;
}

// --- the palpation -------------------------------------------------------------------------------

double FemPalpationPath::length_m() const {
  return (pressed_m - start_m).norm() + (slid_m - pressed_m).norm() + (end_m - slid_m).norm();
}

Vec3 FemPalpationPath::at(double s_m) const {
  const std::array<Vec3, 4> corners{start_m, pressed_m, slid_m, end_m};
  double s = std::max(0.0, s_m);
  for (std::size_t k = 0; k + 1 < corners.size(); ++k) {
    const double leg = (corners[k + 1] - corners[k]).norm();
    if (s <= leg || k + 2 == corners.size()) {
      return corners[k] + (corners[k + 1] - corners[k]) * std::min(1.0, s / leg);
    }
    s -= leg;
  }
  return end_m;
}

FemPalpationPath fem_palpation_path(const FemBlockSpec& spec, double depth_m) {
  const double touch_z = spec.size_m.z() + spec.tool_radius_m;
  const double x0 = -0.5 * kSlideM;
  FemPalpationPath p;
  p.start_m = Vec3(x0, 0.0, touch_z + kClearanceM);
  p.pressed_m = Vec3(x0, 0.0, touch_z - depth_m);
  p.slid_m = Vec3(x0 + kSlideM, 0.0, touch_z - depth_m);
  p.end_m = Vec3(x0 + kSlideM, 0.0, touch_z + kClearanceM);
  return p;
}

double FemErrorRow::max_error_percent() const {
  return peak_force_n > 0.0 ? 100.0 * max_error_n / peak_force_n : 0.0;
}

double FemErrorRow::rms_error_percent() const {
  return peak_force_n > 0.0 ? 100.0 * rms_error_n / peak_force_n : 0.0;
}

double fem_error_target_fraction(double speed_m_per_s) {
  if (std::abs(speed_m_per_s - 0.010) < 1e-9) {
    return 0.05;
  }
  if (std::abs(speed_m_per_s - 0.050) < 1e-9) {
    return 0.10;
  }
  return 0.0;
}

bool fem_error_meets_target(const FemErrorRow& row) {
  const double fraction = fem_error_target_fraction(row.speed_m_per_s);
  if (fraction <= 0.0) {
    return true;
  }
  // 10 mm/s: "within 5 % (or 0.05 N)"; 50 mm/s: within 10 %.
  const double floor_n = fraction <= 0.05 ? 0.05 : 0.0;
  return row.max_error_n <= std::max(fraction * row.peak_force_n, floor_n);
}

FemLocalModelError measure_fem_local_model_error(FemBlockSpec spec,
                                                 const std::vector<double>& speeds_m_per_s,
                                                 double depth_m, double reference_spacing_m,
                                                 const ProgressFn& progress) {
  spec.integration = FemIntegration::kQuasiStatic;
  const FemPalpationPath path = fem_palpation_path(spec, depth_m);
  const double length = path.length_m();
  FemLocalModelError out;
  // The full solve along the path (it depends on the position only: quasi-static, elastic,
  // frictionless), once for every speed.
  const auto intervals =
      static_cast<std::size_t>(std::ceil(length / std::max(reference_spacing_m, 1e-6)));
  const double ds = length / static_cast<double>(intervals);
  std::vector<Vec3> reference(intervals + 1, Vec3::Zero());
  std::vector<char> defined(intervals + 1, 0);
  {
    const Stopwatch watch;
    FemContactReference full(spec);
    for (std::size_t j = 0; j <= intervals; ++j) {
      const std::optional<Vec3> f = full.force_at(path.at(static_cast<double>(j) * ds));
      if (f) {
        reference[j] = *f;
        defined[j] = 1;
      } else if (out.first_unconverged_at_m < 0.0) {
        out.first_unconverged_at_m = static_cast<double>(j) * ds;
      }
      if (j % 32 == 0) {
        report_progress(progress, "full solve along the path",
                        0.5 * static_cast<double>(j) / static_cast<double>(intervals));
      }
    }
    out.reference_points = intervals + 1;
    out.reference_solves = full.solves;
    out.reference_max_iterations = full.max_iterations;
    out.reference_unconverged = full.unconverged;
    out.reference_ms = watch.elapsed_ms();
  }
  // Linear between reference points; undefined next to a point without an equilibrium.
  const auto reference_at = [&](double s) -> std::optional<Vec3> {
    const double u = std::clamp(s / ds, 0.0, static_cast<double>(intervals));
    const auto j = std::min(static_cast<std::size_t>(u), intervals - 1);
    const double f = u - static_cast<double>(j);
    if ((!defined[j] && f < 1.0) || (!defined[j + 1] && f > 0.0)) {
      return std::nullopt;
    }
    return Vec3((1.0 - f) * reference[j] + f * reference[j + 1]);
  };
  double peak = 0.0;
  for (const Vec3& f : reference) {
    peak = std::max(peak, f.norm());
  }
  {
    const double slide_from_m = (path.pressed_m - path.start_m).norm();
    const double slide_to_m = slide_from_m + (path.slid_m - path.pressed_m).norm();
    double lo = std::numeric_limits<double>::infinity();
    double hi = 0.0;
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t j = 0; j <= intervals; ++j) {
      const double s = static_cast<double>(j) * ds;
      if (defined[j] && s >= slide_from_m && s <= slide_to_m) {
        const double f = reference[j].norm();
        lo = std::min(lo, f);
        hi = std::max(hi, f);
        sum += f;
        ++n;
      }
    }
    if (n > 0 && sum > 0.0) {
      out.slide_ripple_percent = 100.0 * (hi - lo) / (sum / static_cast<double>(n));
    }
  }

  for (std::size_t k = 0; k < speeds_m_per_s.size(); ++k) {
    const double v = speeds_m_per_s[k];
    char label[64];
    std::snprintf(label, sizeof label, "local model at %.0f mm/s", v * 1e3);
    report_progress(
        progress, label,
        0.5 + 0.5 * static_cast<double>(k) / static_cast<double>(speeds_m_per_s.size()));
    World world(fem_block_world(spec));
    world.set_fem_deferred(true);
    const double duration = 2.0 * kFemPathHoldS + length / v;
    const auto steps = static_cast<std::size_t>(std::lround(duration / kHapticDtS));
    const ContactMaterial& material = world.description().materials[0].contact;
    FemErrorRow row;
    row.speed_m_per_s = v;
    row.steps = steps;
    row.peak_force_n = peak;
    double sum2 = 0.0;
    double sum2_spring = 0.0;
    for (std::size_t i = 0; i < steps; ++i) {
      const double t = static_cast<double>(i) * kHapticDtS;
      const double s = std::clamp(v * (t - kFemPathHoldS), 0.0, length);
      const Vec3 p = path.at(s);
      const Vec3 rendered = world.step(probe_at(p, t), kHapticDtS).command.force_world_n;
      // The model's spring alone (the stage's push before its damping), at this position.
      const LocalContactModel& model = world.state().fem_contacts[0].model;
      Vec3 spring = Vec3::Zero();
      if (model.valid && (p - model.x0_world_m).norm() <= model.validity_radius_m) {
        const double push =
            model.normal_world.dot(local_model_force(model, p, model.v0_world_m_per_s));
        if (push > 0.0 && std::isfinite(push)) {
          spring = std::min(push, std::min(model.max_normal_force_n, material.max_force_n)) *
                   model.normal_world;
        }
      }
      world.advance_fem();
      row.peak_rendered_n = std::max(row.peak_rendered_n, rendered.norm());
      const std::optional<Vec3> defined_ref = reference_at(s);
      if (!defined_ref) {
        ++row.undefined_steps;
        continue;
      }
      const Vec3& ref = *defined_ref;
      if (rendered.norm() > 0.0 || ref.norm() > 0.0) {
        ++row.contact_steps;
        const double e = (rendered - ref).norm();
        const double e_spring = (spring - ref).norm();
        sum2 += e * e;
        sum2_spring += e_spring * e_spring;
        if (e > row.max_error_n) {
          row.max_error_n = e;
          row.max_error_at_m = s;
        }
        row.max_spring_error_n = std::max(row.max_spring_error_n, e_spring);
      }
    }
    if (row.contact_steps > 0) {
      row.rms_error_n = std::sqrt(sum2 / static_cast<double>(row.contact_steps));
      row.rms_spring_error_n = std::sqrt(sum2_spring / static_cast<double>(row.contact_steps));
    }
    out.rows.push_back(row);
  }
  return out;
}

// --- the whole benchmark -------------------------------------------------------------------------

namespace {

void measure_solver(const FemBlockSpec& spec, int steps, FemBenchRow& row) {
  FemBlockSpec dynamic = spec;
  dynamic.integration = FemIntegration::kBackwardEuler;
  TetMesh tets = block_tets(dynamic);
  const TetBoundary boundary = tet_boundary(tets);
  const std::vector<std::uint32_t> fixed = bottom_nodes(tets);
  const Stopwatch build;
  FemBody body(std::move(tets), std::vector<FemRegionMaterial>{FemRegionMaterial{0, spec.material}},
               fixed, block_options(dynamic), "fem bench");
  row.build_ms = build.elapsed_ms();
  row.tets = body.tet_count();
  row.nodes = body.node_count();
  row.unknowns = body.unknowns();
  row.factorisation_ms = body.factorisation_ms();
  row.factor_memory_bytes = body.factor_memory_bytes();
  row.factor_nonzeros = body.factor_nonzeros();
  // The press: on the top's centre, over the coupling's patch about it.
  std::vector<FemNodeWeight> patch;
  rest_patch(
      boundary.surface, boundary.node_of_vertex, Vec3(0.0, 0.0, spec.size_m.z()),
      std::max(fem_patch_radius_m(spec.patch_radius_m, boundary.surface), spec.tool_radius_m),
      patch);
  std::vector<FemNodeForce> loads;
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(steps));
  long cg_sum = 0;
  for (int i = 0; i < steps; ++i) {
    const double t = (i + 1) * spec.dt_s;
    const double f =
        kPressPeakN * 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * t / kPressPeriodS));
    loads.clear();
    for (const FemNodeWeight& w : patch) {
      loads.push_back({w.node, Vec3(0.0, 0.0, -f * w.weight)});
    }
    body.set_loads(loads);
    const Stopwatch watch;
    const FemStepStats stats = body.step();
    ms.push_back(watch.elapsed_ms());
    cg_sum += stats.cg_iterations;
    row.cg_iterations_max = std::max(row.cg_iterations_max, stats.cg_iterations);
    row.unconverged_steps += stats.converged ? 0U : 1U;
  }
  row.fem_steps = ms.size();
  row.cg_iterations_mean = steps > 0 ? static_cast<double>(cg_sum) / steps : 0.0;
  const SampleSummary s = summarize_samples(ms);
  row.step_ms_p50 = s.p50;
  row.step_ms_p99 = s.p99;
  row.step_ms_max = s.max;
  row.step_ms_mean = s.mean;
}

void measure_haptic(const FemBlockSpec& spec, double seconds, double depth_m, FemBenchRow& row) {
  FemBlockSpec dynamic = spec;
  dynamic.integration = FemIntegration::kBackwardEuler;
  World world(fem_block_world(dynamic));
  world.set_fem_deferred(true);  // FEM updates between cycles, as `hapsim run` does
  const FemPalpationPath path = fem_palpation_path(dynamic, depth_m);
  // Down into the top at the slide's start (untimed).
  const double down_m = (path.pressed_m - path.start_m).norm();
  const auto down_steps =
      static_cast<std::size_t>(std::lround(down_m / kHapticSpeedMPerS / kHapticDtS));
  double t = 0.0;
  for (std::size_t i = 0; i <= down_steps; ++i) {
    const double f = static_cast<double>(i) / static_cast<double>(down_steps);
    (void)world.step(probe_at(path.start_m + f * (path.pressed_m - path.start_m), t), kHapticDtS);
    world.advance_fem();
    t += kHapticDtS;
  }
  const std::size_t updates_before = world.fem()->stats().update_ms.size();
  const auto steps = static_cast<std::size_t>(std::lround(seconds / kHapticDtS));
  std::vector<double> us;
  us.reserve(steps);
  const double leg_s = kSlideM / kHapticSpeedMPerS;
  for (std::size_t i = 0; i < steps; ++i) {
    // To and fro along the slide, pressed.
    const double phase = std::fmod(static_cast<double>(i + 1) * kHapticDtS, 2.0 * leg_s) / leg_s;
    const double f = phase <= 1.0 ? phase : 2.0 - phase;
    const DeviceInput in = probe_at(path.pressed_m + f * (path.slid_m - path.pressed_m), t);
    const Stopwatch watch;
    const StepResult& r = world.step(in, kHapticDtS);
    us.push_back(watch.elapsed_s() * 1e6);
    row.haptic_contact_steps += r.tools[0].contact_count > 0 ? 1U : 0U;
    row.haptic_peak_force_n = std::max(row.haptic_peak_force_n, r.command.force_world_n.norm());
    world.advance_fem();  // outside the timed region
    t += kHapticDtS;
  }
  row.haptic_steps = us.size();
  const SampleSummary s = summarize_samples(us);
  row.haptic_us_p50 = s.p50;
  row.haptic_us_p99 = s.p99;
  row.haptic_us_max = s.max;
  row.haptic_us_mean = s.mean;
  const std::vector<double>& all = world.fem()->stats().update_ms;
  std::vector<double> update_ms(all.begin() + static_cast<std::ptrdiff_t>(updates_before),
                                all.end());
  row.fem_updates = update_ms.size();
  const SampleSummary u = summarize_samples(update_ms);
  row.update_ms_p50 = u.p50;
  row.update_ms_max = u.max;
}

}  // namespace

FemBenchResult run_fem_bench(const FemBenchOptions& options) {
  FemBenchResult result;
  result.options = options;
  result.options.progress = nullptr;
  const std::size_t total = options.tet_counts.size() * options.elasticities.size();
  std::size_t done = 0;
  for (const std::size_t target : options.tet_counts) {
    for (const FemElasticity elasticity : options.elasticities) {
      if (options.stop != nullptr && options.stop->load(std::memory_order_relaxed)) {
        return result;
      }
      FemBlockSpec spec;
      spec.cells = fem_block_cells(spec.size_m, target);
      spec.elasticity = elasticity;
      result.block = spec;
      FemBenchRow row;
      row.target_tets = target;
      row.cells = spec.cells;
      row.elasticity = elasticity;
      const std::string name = std::to_string(6 * spec.cells[0] * spec.cells[1] * spec.cells[2]) +
                               " tets " + elasticity_name(elasticity);
      const auto at = [&](double part) {
        return (static_cast<double>(done) + part) / static_cast<double>(total);
      };
      report_progress(options.progress, name + ": FEM steps", at(0.0));
      measure_solver(spec, options.fem_steps, row);
      report_progress(options.progress, name + ": haptic steps", at(0.2));
      measure_haptic(spec, options.haptic_s, options.depth_m, row);
      if (options.measure_error && !options.speeds_m_per_s.empty()) {
        const ProgressFn inner = [&](std::string_view label, double fraction) {
          report_progress(options.progress, name + ": " + std::string(label),
                          at(0.3 + 0.7 * fraction));
        };
        row.error = measure_fem_local_model_error(spec, options.speeds_m_per_s, options.depth_m,
                                                  options.reference_spacing_m, inner);
        row.error_measured = true;
      }
      result.rows.push_back(std::move(row));
      ++done;
    }
  }
  report_progress(options.progress, "done", 1.0);
  return result;
}

std::string format_fem_table(const FemBenchResult& result) {
  std::ostringstream out;
  char line[400];
  std::snprintf(line, sizeof line, "%6s %6s %-12s %8s %9s %9s %15s %17s %11s %15s %21s\n", "tets",
                "nodes", "elasticity", "build_ms", "factor_ms", "factor_MB", "step_ms p50/max",
                "rate_Hz med/worst", "CG mean/max", "update_ms p50/max", "haptic_us p50/p99/max");
  out << line;
  for (const FemBenchRow& r : result.rows) {
    char step[32];
    char rate[32];
    char cg[32];
    char update[32];
    char haptic[40];
    std::snprintf(step, sizeof step, "%.2f/%.2f", r.step_ms_p50, r.step_ms_max);
    std::snprintf(rate, sizeof rate, "%.0f/%.0f", r.rate_hz_median(), r.rate_hz_worst());
    std::snprintf(cg, sizeof cg, "%.1f/%d", r.cg_iterations_mean, r.cg_iterations_max);
    std::snprintf(update, sizeof update, "%.2f/%.2f", r.update_ms_p50, r.update_ms_max);
    std::snprintf(haptic, sizeof haptic, "%.1f/%.1f/%.1f", r.haptic_us_p50, r.haptic_us_p99,
                  r.haptic_us_max);
    std::snprintf(line, sizeof line, "%6zu %6zu %-12s %8.1f %9.1f %9.2f %15s %17s %11s %15s %21s\n",
                  r.tets, r.nodes, elasticity_name(r.elasticity).c_str(), r.build_ms,
                  r.factorisation_ms, static_cast<double>(r.factor_memory_bytes) / 1e6, step, rate,
                  cg, update, haptic);
    out << line;
  }
  bool header = false;
  for (const FemBenchRow& r : result.rows) {
    if (!r.error_measured) {
      continue;
    }
    if (!header) {
      std::snprintf(
          line, sizeof line,
          "\nLocal model vs the full solve (quasi-static; the contact spring in series at "
          "the device position), palpation %.1f mm deep, 20 mm sideways; undefined: "
          "steps next to a path point where the contact law has no equilibrium (left "
          "out; from: where along the path, mm; a starred verdict is on the rest "
          "only); spring: the model's f0 + K(x - x0) without the stage's damping:\n",
          result.options.depth_m * 1e3);
      out << line;
      std::snprintf(line, sizeof line,
                    "%6s %-12s %6s %7s %9s %7s %9s %7s %12s %8s %4s %15s %9s %8s\n", "tets",
                    "elasticity", "mm/s", "peak_N", "max_err_N", "max_%", "rms_err_N", "rms_%",
                    "spring_max_N", "target", "met", "undefined/steps", "from_mm", "ripple_%");
      out << line;
      header = true;
    }
    for (const FemErrorRow& e : r.error.rows) {
      const double fraction = fem_error_target_fraction(e.speed_m_per_s);
      char target[24] = "-";
      if (fraction > 0.0) {
        std::snprintf(target, sizeof target, fraction <= 0.05 ? "%.0f%%|0.05N" : "%.0f%%",
                      100.0 * fraction);
      }
      char undefined[40];
      std::snprintf(undefined, sizeof undefined, "%zu/%zu", e.undefined_steps, e.steps);
      char from[24] = "-";
      if (r.error.first_unconverged_at_m >= 0.0) {
        std::snprintf(from, sizeof from, "%.1f", r.error.first_unconverged_at_m * 1e3);
      }
      std::snprintf(
          line, sizeof line,
          "%6zu %-12s %6.0f %7.3f %9.4f %7.2f %9.4f %7.2f %12.4f %8s %4s %15s %9s %8.1f\n", r.tets,
          elasticity_name(r.elasticity).c_str(), e.speed_m_per_s * 1e3, e.peak_force_n,
          e.max_error_n, e.max_error_percent(), e.rms_error_n, e.rms_error_percent(),
          e.max_spring_error_n, target,
          fraction > 0.0 ? (fem_error_meets_target(e) ? (e.undefined_steps > 0 ? "yes*" : "yes")
                                                      : (e.undefined_steps > 0 ? "NO*" : "NO"))
                         : "-",
          undefined, from, r.error.slide_ripple_percent);
      out << line;
    }
  }
  return out.str();
}

nlohmann::json fem_bench_to_json(const FemBenchResult& result) {
  const FemBlockSpec& b = result.block;
  nlohmann::json rows = nlohmann::json::array();
  for (const FemBenchRow& r : result.rows) {
    nlohmann::json row{
        {"target_tets", r.target_tets},
        {"cells", r.cells},
        {"tets", r.tets},
        {"nodes", r.nodes},
        {"unknowns", r.unknowns},
        {"elasticity", elasticity_name(r.elasticity)},
        {"build_ms", r.build_ms},
        {"factorisation_ms", r.factorisation_ms},
        {"factor_memory_bytes", r.factor_memory_bytes},
        {"factor_memory_mb", static_cast<double>(r.factor_memory_bytes) / 1e6},
        {"factor_nonzeros", r.factor_nonzeros},
        {"fem_step",
         {{"steps", r.fem_steps},
          {"ms",
           {{"p50", r.step_ms_p50},
            {"p99", r.step_ms_p99},
            {"max", r.step_ms_max},
            {"mean", r.step_ms_mean}}},
          {"rate_hz", {{"median", r.rate_hz_median()}, {"worst", r.rate_hz_worst()}}},
          {"cg_iterations", {{"mean", r.cg_iterations_mean}, {"max", r.cg_iterations_max}}},
          {"unconverged_steps", r.unconverged_steps}}},
        {"fem_update",
         {{"updates", r.fem_updates},
          {"ms", {{"p50", r.update_ms_p50}, {"max", r.update_ms_max}}}}},
        {"haptic_step",
         {{"steps", r.haptic_steps},
          {"contact_steps", r.haptic_contact_steps},
          {"us",
           {{"p50", r.haptic_us_p50},
            {"p99", r.haptic_us_p99},
            {"max", r.haptic_us_max},
            {"mean", r.haptic_us_mean}}},
          {"peak_force_n", r.haptic_peak_force_n}}},
    };
    if (r.error_measured) {
      nlohmann::json speeds = nlohmann::json::array();
      for (const FemErrorRow& e : r.error.rows) {
        const double fraction = fem_error_target_fraction(e.speed_m_per_s);
        speeds.push_back({{"speed_mm_per_s", e.speed_m_per_s * 1e3},
                          {"steps", e.steps},
                          {"undefined_steps", e.undefined_steps},
                          {"contact_steps", e.contact_steps},
                          {"peak_rendered_n", e.peak_rendered_n},
                          {"peak_force_n", e.peak_force_n},
                          {"max_error_n", e.max_error_n},
                          {"rms_error_n", e.rms_error_n},
                          {"max_error_percent", e.max_error_percent()},
                          {"rms_error_percent", e.rms_error_percent()},
                          {"max_spring_error_n", e.max_spring_error_n},
                          {"rms_spring_error_n", e.rms_spring_error_n},
                          {"max_error_at_path_m", e.max_error_at_m},
                          {"target_fraction",
                           fraction > 0.0 ? nlohmann::json(fraction) : nlohmann::json(nullptr)},
                          // Undecided where part of the path has no reference.
                          {"meets_target", fraction > 0.0 && e.undefined_steps == 0
                                               ? nlohmann::json(fem_error_meets_target(e))
                                               : nlohmann::json(nullptr)},
                          {"meets_target_where_defined",
                           fraction > 0.0 ? nlohmann::json(fem_error_meets_target(e))
                                          : nlohmann::json(nullptr)}});
      }
      row["local_model_error"] = {
          {"speeds", speeds},
          {"reference",
           {{"points", r.error.reference_points},
            {"solves", r.error.reference_solves},
            {"max_iterations", r.error.reference_max_iterations},
            {"unconverged", r.error.reference_unconverged},
            {"first_unconverged_at_path_m", r.error.first_unconverged_at_m >= 0.0
                                                ? nlohmann::json(r.error.first_unconverged_at_m)
                                                : nlohmann::json(nullptr)},
            {"ms", r.error.reference_ms},
            {"slide_ripple_percent", r.error.slide_ripple_percent}}}};
    } else {
      row["local_model_error"] = nullptr;
    }
    rows.push_back(std::move(row));
  }
  const FemPalpationPath path = fem_palpation_path(b, result.options.depth_m);
  return {
      {"block",
       {{"generator", "make_tet_block"},
        {"size_m", {b.size_m.x(), b.size_m.y(), b.size_m.z()}},
        {"fixed", "bottom face (z = 0)"},
        {"material",
         {{"youngs_modulus_pa", b.material.youngs_modulus_pa},
          {"poisson_ratio", b.material.poisson_ratio},
          {"density_kg_per_m3", b.material.density_kg_per_m3},
          {"rayleigh_mass_per_s", b.material.rayleigh_mass_per_s},
          {"rayleigh_stiffness_s", b.material.rayleigh_stiffness_s}}},
        {"contact",
         {{"stiffness_n_per_m", b.contact_stiffness_n_per_m},
          {"damping_n_s_per_m", b.contact_damping_n_s_per_m},
          {"max_force_n", b.max_force_n},
          {"tool_radius_m", b.tool_radius_m},
          {"patch_radius_m", b.patch_radius_m}}}}},
      {"fem_step",
       {{"integration", "backward_euler"},
        {"dt_s", b.dt_s},
        {"steps", result.options.fem_steps},
        {"threads", 1},
        {"load",
         "0 -> 2 N -> 0 once a second (half-cosine) on the contact patch at the top's centre"}}},
      {"haptic_step",
       {{"integration", "backward_euler"},
        {"fem_deferred", true},
        {"timed", "World::step only; advance_fem() between cycles, untimed (as hapsim run)"},
        {"motion", "pressed depth_m beyond the first touch, to and fro 20 mm along x at 20 mm/s"},
        {"depth_m", result.options.depth_m},
        {"seconds", result.options.haptic_s}}},
      {"local_model_error",
       {{"integration", "quasi_static"},
        {"reference",
         "quasi-static equilibrium of the FEM body with the contact spring in series at the device "
         "position, under the coupling's contact law (world/fem_coupling.cpp): the contact point "
         "is "
         "the rest surface's closest point to the tool less the patch's displacement, the load is "
         "spread on the rest-surface vertices within the patch radius (weights 1-(r/R)^2) along "
         "the "
         "patch's rest normal, F = k_c * (tool radius - n.(p - (contact point + patch "
         "displacement))); solved independently of the world by Newton on F (slope 1 + k_c * the "
         "patch's condensed compliance), each iterate a quasi-static FemBody::step (as the "
         "coupling's "
         "update; iterated until the body has settled). Not "
         "solve_static_sphere_contact: a rigid sphere held by node penalties is another contact "
         "law"},
        {"reference_spacing_m", result.options.reference_spacing_m},
        {"interpolation", "linear in path length between reference points"},
        {"error",
         "|F_rendered - F_reference| (vectors); rms over steps where either is non-zero; "
         "percent of the path's peak reference force"},
        {"path",
         {{"start_m", {path.start_m.x(), path.start_m.y(), path.start_m.z()}},
          {"pressed_m", {path.pressed_m.x(), path.pressed_m.y(), path.pressed_m.z()}},
          {"slid_m", {path.slid_m.x(), path.slid_m.y(), path.slid_m.z()}},
          {"end_m", {path.end_m.x(), path.end_m.y(), path.end_m.z()}},
          {"depth_m", result.options.depth_m},
          {"slide_m", kSlideM},
          {"hold_s", kFemPathHoldS}}},
        {"targets", {{"10_mm_per_s", "5 % of peak or 0.05 N"}, {"50_mm_per_s", "10 % of peak"}}}}},
      {"rows", rows}};
}

}  // namespace hapsim::bench
