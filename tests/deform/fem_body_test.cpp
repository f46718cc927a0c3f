#include "hapsim/deform/fem_body.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/tet_mesh.h"

#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

// Heap allocations through malloc, counted per thread: Eigen's dynamic matrices allocate with
// malloc, not operator new, so the project's counter (operator new) alone would miss a temporary
// vector in a solve. Interposed in this executable only; not under a sanitizer, which owns malloc.
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define HAPSIM_FEM_TEST_COUNTS_MALLOC 1
namespace {
thread_local long t_fem_test_mallocs = 0;
}  // namespace
extern "C" void* __libc_malloc(std::size_t size);     // NOLINT(bugprone-reserved-identifier)
extern "C" void* malloc(std::size_t size) noexcept {  // NOLINT(cert-dcl58-cpp)
  ++t_fem_test_mallocs;
  return __libc_malloc(size);
}
#endif

namespace hapsim {
namespace {

long fem_test_mallocs() {
#ifdef HAPSIM_FEM_TEST_COUNTS_MALLOC
  return t_fem_test_mallocs;
#else
  return 0;
#endif
}

FemMaterial material(double youngs_pa, double poisson, double density = 1000.0) {
  FemMaterial m;
  m.youngs_modulus_pa = youngs_pa;
  m.poisson_ratio = poisson;
  m.density_kg_per_m3 = density;
  return m;
}

FemOptions options(FemElasticity elasticity, FemIntegration integration) {
  FemOptions o;
  o.elasticity = elasticity;
  o.integration = integration;
  return o;
}

constexpr FemElasticity kLinear = FemElasticity::kLinear;
constexpr FemElasticity kCorotational = FemElasticity::kCorotational;
constexpr FemIntegration kStatic = FemIntegration::kQuasiStatic;
constexpr FemIntegration kEuler = FemIntegration::kBackwardEuler;

std::vector<std::uint32_t> nodes_where(const TetMesh& mesh,
                                       const std::function<bool(const Vec3&)>& pred) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    if (pred(mesh.nodes[i])) {
      out.push_back(static_cast<std::uint32_t>(i));
    }
  }
  return out;
}

// Triangles that belong to one tet only (written out here, independently of tet_boundary()).
std::vector<std::array<std::uint32_t, 3>> boundary_faces(const TetMesh& mesh) {
  std::map<std::array<std::uint32_t, 3>, int> count;
  for (const TetIndices& t : mesh.tets) {
    for (std::size_t skip = 0; skip < 4; ++skip) {
      std::array<std::uint32_t, 3> f{};
      std::size_t k = 0;
      for (std::size_t i = 0; i < 4; ++i) {
        if (i != skip) {
          f[k++] = t[i];
        }
      }
      std::sort(f.begin(), f.end());
      ++count[f];
    }
  }
  std::vector<std::array<std::uint32_t, 3>> out;
  for (const auto& [face, n] : count) {
    if (n == 1) {
      out.push_back(face);
    }
  }
  return out;
}

// Consistent nodal forces of a uniform traction (N/m²) on the boundary faces whose three nodes
// satisfy `on_face`: a linear triangle gives a third of area·traction to each of its nodes.
std::vector<FemNodeForce> traction_loads(const TetMesh& mesh,
                                         const std::function<bool(const Vec3&)>& on_face,
                                         const Vec3& traction_pa) {
  std::map<std::uint32_t, Vec3> force;
  for (const auto& f : boundary_faces(mesh)) {
    const Vec3& a = mesh.nodes[f[0]];
    const Vec3& b = mesh.nodes[f[1]];
    const Vec3& c = mesh.nodes[f[2]];
    if (!on_face(a) || !on_face(b) || !on_face(c)) {
      continue;
    }
    const double area = 0.5 * (b - a).cross(c - a).norm();
    for (const std::uint32_t n : f) {
      auto [it, inserted] = force.try_emplace(n, Vec3::Zero());
      it->second += area / 3.0 * traction_pa;
    }
  }
  std::vector<FemNodeForce> out;
  for (const auto& [node, f] : force) {
    out.push_back({node, f});
  }
  return out;
}

Vec3 total_force(const std::vector<FemNodeForce>& loads) {
  Vec3 sum = Vec3::Zero();
  for (const FemNodeForce& l : loads) {
    sum += l.force_n;
  }
  return sum;
}

Mat3 lame_stress(const Mat3& strain, double youngs_pa, double poisson) {
  const double lambda = youngs_pa * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
  const double mu = youngs_pa / (2.0 * (1.0 + poisson));
  return lambda * strain.trace() * Mat3::Identity() + 2.0 * mu * strain;
}

// ---------------------------------------------------------------------------------------------

// Patch test: on an irregular mesh whose boundary nodes follow a linear displacement field, the
// interior nodes reproduce the field and every element carries the same stress, D·ε.
TEST(FemBody, PatchTestReproducesLinearFieldOnIrregularMesh) {
  const double h = 0.01;
  TetMesh mesh = make_tet_block(Vec3(4 * h, 3 * h, 5 * h), {4, 3, 5});
  const Box3 box = mesh.bounds();
  const auto on_boundary = [&](const Vec3& p) {
    return (p - box.min()).minCoeff() < 1e-12 || (box.max() - p).minCoeff() < 1e-12;
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.2 * h, 0.2 * h);
  for (Vec3& p : mesh.nodes) {
    if (!on_boundary(p)) {
      p += Vec3(jitter(rng), jitter(rng), jitter(rng));
    }
  }
  const std::vector<std::uint32_t> boundary = nodes_where(mesh, on_boundary);
  ASSERT_LT(boundary.size(), mesh.node_count());  // there are interior nodes to test
  Mat3 grad;
  grad << 2e-3, -1e-3, 0.5e-3, 0.7e-3, -1.5e-3, 1.2e-3, -0.4e-3, 0.9e-3, 3e-3;
  const Vec3 offset(1e-4, -2e-4, 0.5e-4);
  const auto field = [&](const Vec3& p) { return Vec3(p + grad * p + offset); };
  const double youngs = 20e3;
  const double poisson = 0.35;
  FemBody body(mesh, {{0, material(youngs, poisson)}}, boundary, options(kLinear, kStatic));
  std::vector<Vec3> held;
  for (const std::uint32_t n : body.fixed_nodes()) {
    held.push_back(field(mesh.nodes[n]));
  }
  body.set_fixed_positions(held);
  body.solve_static();
  const double scale = grad.norm() * box.diagonal().norm();
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    EXPECT_LT((body.positions()[i] - field(mesh.nodes[i])).norm(), 1e-9 * scale) << "node " << i;
  }
  const Mat3 sigma = lame_stress(0.5 * (grad + grad.transpose()), youngs, poisson);
  std::vector<Mat3> stress;
  body.element_stress_pa(stress);
  ASSERT_EQ(stress.size(), mesh.tet_count());
  for (std::size_t t = 0; t < stress.size(); ++t) {
    EXPECT_LT((stress[t] - sigma).norm(), 1e-8 * sigma.norm()) << "tet " << t;
  }
}

// The corotational model passes the patch test of a stretched *and rotated* field
// x = R₀·(I + E)·X: each element's rotation is R₀, its strain E, its stress R₀·D(E)·R₀ᵀ.
TEST(FemBody, CorotationalPatchTestWithLargeRotation) {
  const double h = 0.01;
  TetMesh mesh = make_tet_block(Vec3(3 * h, 3 * h, 4 * h), {3, 3, 4});
  const Box3 box = mesh.bounds();
  const auto on_boundary = [&](const Vec3& p) {
    return (p - box.min()).minCoeff() < 1e-12 || (box.max() - p).minCoeff() < 1e-12;
  };
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.2 * h, 0.2 * h);
  for (Vec3& p : mesh.nodes) {
    if (!on_boundary(p)) {
      p += Vec3(jitter(rng), jitter(rng), jitter(rng));
    }
  }
  Mat3 strain;
  strain << 4e-3, 1e-3, -2e-3, 1e-3, -3e-3, 0.5e-3, -2e-3, 0.5e-3, 2e-3;
  const Mat3 rot = Eigen::AngleAxisd(0.6, Vec3(1, 2, 2).normalized()).toRotationMatrix();
  const auto field = [&](const Vec3& p) { return Vec3(rot * (p + strain * p)); };
  FemOptions o = options(kCorotational, kStatic);
  o.cg_relative_tolerance = 1e-12;
  FemBody body(mesh, {{0, material(10e3, 0.3)}}, nodes_where(mesh, on_boundary), o);
  std::vector<Vec3> held;
  for (const std::uint32_t n : body.fixed_nodes()) {
    held.push_back(field(mesh.nodes[n]));
  }
  body.set_fixed_positions(held);
  const FemStepStats stats = body.solve_static();
  EXPECT_TRUE(stats.converged);
  const double scale = box.diagonal().norm();
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    EXPECT_LT((body.positions()[i] - field(mesh.nodes[i])).norm(), 1e-9 * scale) << "node " << i;
  }
  const Mat3 sigma = rot * lame_stress(strain, 10e3, 0.3) * rot.transpose();
  std::vector<Mat3> stress;
  body.element_stress_pa(stress);
  for (std::size_t t = 0; t < stress.size(); ++t) {
    EXPECT_LT((stress[t] - sigma).norm(), 1e-6 * sigma.norm()) << "tet " << t;
  }
}

// A bar under axial traction, ν = 0 (so the clamped end does not constrain the lateral
// contraction): σ = F/A in every element, u = F·X/(E·A), elongation F·L/(E·A).
TEST(FemBody, UniaxialBarStressIsEStrain) {
  const double length = 0.1;
  const double side = 0.02;
  const double youngs = 50e3;
  const double force = 0.8;
  const TetMesh mesh = make_tet_block(Vec3(length, side, side), {10, 2, 2});
  const auto loads = traction_loads(
      mesh, [&](const Vec3& p) { return p.x() > length - 1e-12; },
      Vec3(force / (side * side), 0.0, 0.0));
  ASSERT_NEAR(total_force(loads).x(), force, 1e-12);
  const auto clamped = nodes_where(mesh, [](const Vec3& p) { return p.x() < 1e-12; });
  for (const FemElasticity model : {kLinear, kCorotational}) {
    SCOPED_TRACE(std::string(to_string(model)));
    FemOptions o = options(model, kStatic);
    o.cg_relative_tolerance = 1e-12;
    FemBody body(mesh, {{0, material(youngs, 0.0)}}, clamped, o);
    body.set_loads(loads);
    body.solve_static();
    const double strain = force / (youngs * side * side);
    for (std::size_t i = 0; i < mesh.node_count(); ++i) {
      const Vec3 expected(strain * mesh.nodes[i].x(), 0.0, 0.0);
      // Corotational: the finite-rotation model differs from the small-strain one at O(ε²).
      EXPECT_LT((body.displacement(static_cast<std::uint32_t>(i)) - expected).norm(),
                1e-6 * strain * length);
    }
    double tip = 0.0;
    const auto tip_nodes = nodes_where(mesh, [&](const Vec3& p) { return p.x() > length - 1e-12; });
    for (const std::uint32_t n : tip_nodes) {
      tip += body.displacement(n).x() / static_cast<double>(tip_nodes.size());
    }
    EXPECT_NEAR(tip, force * length / (youngs * side * side), 1e-6 * tip);
    std::vector<Mat3> stress;
    body.element_stress_pa(stress);
    std::vector<double> von_mises;
    body.von_mises_pa(von_mises);
    const double sigma = force / (side * side);
    for (std::size_t t = 0; t < stress.size(); ++t) {
      EXPECT_NEAR(stress[t](0, 0), sigma, 1e-6 * sigma);
      EXPECT_NEAR(stress[t](0, 0) / (tip / length), youngs, 1e-6 * youngs);  // σ = E·ε
      EXPECT_LT((stress[t] - sigma * Vec3::UnitX() * Vec3::UnitX().transpose()).norm(),
                1e-6 * sigma);
      EXPECT_NEAR(von_mises[t], sigma, 1e-6 * sigma);
    }
    // The support takes the load: the elastic forces on the clamped nodes sum to +F.
    std::vector<Vec3> elastic;
    body.elastic_forces(elastic);
    Vec3 reaction = Vec3::Zero();
    for (const std::uint32_t n : clamped) {
      reaction += elastic[n];
    }
    EXPECT_LT((reaction - Vec3(force, 0, 0)).norm(), 1e-6 * force);
  }
}

// A cantilever under a tip load against beam theory: P·L³/(3·E·I) + P·L/(κ·G·A) (Euler–Bernoulli
// plus Timoshenko's shear term, κ = 5/6: 2.4 % at L/h = 5; ν = 0, so the clamp does not restrain
// a lateral contraction). Linear tets are stiff in bending, the more so the coarser; the error
// falls as the mesh is refined: measured -44.6 %, -17.5 %, -5.1 % with 2, 4, 8 cells through the
// thickness (240, 1 920, 15 360 tets). (At L/h = 10: -45 %, -17.6 %, -8.7 %, -5.1 % with 2, 4, 6,
// 8 cells.)
TEST(FemBody, CantileverConvergesToBeamTheory) {
  const double length = 0.05;
  const double side = 0.01;
  const double youngs = 1e5;
  const double load = 1e-3;  // N, small: linear theory
  const double inertia = side * side * side * side / 12.0;
  const double shear_modulus = youngs / 2.0;  // ν = 0
  const double expected = load * length * length * length / (3.0 * youngs * inertia) +
                          load * length / (5.0 / 6.0 * shear_modulus * side * side);
  std::vector<double> errors;
  for (const int n : {2, 4, 8}) {
    const TetMesh mesh = make_tet_block(Vec3(length, side, side), {5 * n, n, n});
    const auto loads = traction_loads(
        mesh, [&](const Vec3& p) { return p.x() > length - 1e-12; },
        Vec3(0.0, 0.0, -load / (side * side)));
    FemBody body(mesh, {{0, material(youngs, 0.0)}},
                 nodes_where(mesh, [](const Vec3& p) { return p.x() < 1e-12; }),
                 options(kLinear, kStatic));
    body.set_loads(loads);
    body.solve_static();
    // The tip's deflection: the load-weighted mean of the tip face's nodes.
    double deflection = 0.0;
    for (const FemNodeForce& l : loads) {
      deflection += -body.displacement(l.node).z() * (l.force_n.z() / -load);
    }
    errors.push_back(deflection / expected - 1.0);
  }
  for (std::size_t k = 1; k < errors.size(); ++k) {
    EXPECT_LT(std::abs(errors[k]), std::abs(errors[k - 1]));
  }
  EXPECT_LT(errors.front(), 0.0);  // too stiff, not too soft
  EXPECT_LT(std::abs(errors.back()), 0.10)
      << "errors " << errors[0] << " " << errors[1] << " " << errors[2];
}

// A rigid rotation of an unloaded body: the corotational model sees no strain and no force; the
// linear one sees a strain of order 1 (cos 90° − 1) and large forces: why corotational exists.
TEST(FemBody, RigidRotationGivesNoForceOnlyWhenCorotational) {
  const double size = 0.03;
  const double youngs = 10e3;
  const TetMesh mesh = make_tet_block(Vec3::Constant(size), {3, 3, 3});
  const auto bottom = nodes_where(mesh, [](const Vec3& p) { return p.z() < 1e-12; });
  const Mat3 rot =
      Eigen::AngleAxisd(std::numbers::pi / 2.0, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 centre = Vec3::Constant(size / 2.0);
  std::vector<Vec3> rotated;
  for (const Vec3& p : mesh.nodes) {
    rotated.push_back(centre + rot * (p - centre));
  }
  const double force_scale = youngs * size * size;
  const double energy_scale = youngs * size * size * size;
  for (const FemElasticity model : {kLinear, kCorotational}) {
    SCOPED_TRACE(std::string(to_string(model)));
    FemBody body(mesh, {{0, material(youngs, 0.3)}}, bottom, options(model, kEuler));
    body.set_state(rotated);
    std::vector<Vec3> forces;
    body.elastic_forces(forces);
    double largest = 0.0;
    for (const Vec3& f : forces) {
      largest = std::max(largest, f.norm());
    }
    if (model == kCorotational) {
      EXPECT_LT(largest, 1e-10 * force_scale);
      EXPECT_LT(body.elastic_energy_j(), 1e-18 * energy_scale);
      // Stepping the rotated body (the fixed nodes held where they were put) leaves it there.
      for (int k = 0; k < 5; ++k) {
        body.step();
      }
      for (std::size_t i = 0; i < rotated.size(); ++i) {
        EXPECT_LT((body.positions()[i] - rotated[i]).norm(), 1e-9 * size);
      }
    } else {
      EXPECT_GT(largest, 0.05 * force_scale);
      EXPECT_GT(body.elastic_energy_j(), 0.1 * energy_scale);
    }
  }
}

// The tissue's compliance at a point, against the static response to a unit force there; and,
// corotational, the same number for the body rigidly rotated and the direction rotated with it.
TEST(FemBody, ComplianceAlongMatchesStaticResponse) {
  const TetMesh mesh = make_tet_block(Vec3(0.04, 0.04, 0.02), {4, 4, 2});
  const auto bottom = nodes_where(mesh, [](const Vec3& p) { return p.z() < 1e-12; });
  const auto top = nodes_where(mesh, [](const Vec3& p) { return p.z() > 0.02 - 1e-12; });
  const std::vector<FemNodeWeight> point{{top[12], 0.7}, {top[13], 0.3}};
  const Vec3 n = Vec3(0.3, -0.2, -1.0).normalized();
  for (const FemElasticity model : {kLinear, kCorotational}) {
    SCOPED_TRACE(std::string(to_string(model)));
    FemOptions o = options(model, kStatic);
    o.cg_relative_tolerance = 1e-12;
    FemBody body(mesh, {{0, material(5e3, 0.4)}}, bottom, o);
    const double compliance = body.compliance_along(point, n);
    EXPECT_GT(compliance, 0.0);
    const double unit = 1e-6;  // N: small, so the corotational response is linear
    const std::vector<FemNodeForce> loads{{point[0].node, point[0].weight * unit * n},
                                          {point[1].node, point[1].weight * unit * n}};
    body.set_loads(loads);
    body.solve_static();
    const double moved = (point[0].weight * body.displacement(point[0].node) +
                          point[1].weight * body.displacement(point[1].node))
                             .dot(n);
    EXPECT_NEAR(moved / unit, compliance, 1e-6 * compliance);
    if (model == kCorotational) {
      const Mat3 rot = Eigen::AngleAxisd(1.2, Vec3(0.2, 1, -0.4).normalized()).toRotationMatrix();
      std::vector<Vec3> rotated;
      for (const Vec3& p : mesh.nodes) {
        rotated.push_back(rot * p);
      }
      body.set_loads({});
      body.set_state(rotated);
      EXPECT_NEAR(body.compliance_along(point, rot * n), compliance, 1e-9 * compliance);
    }
  }
}

// Corotational statics under a large load: at the equilibrium found, the elastic forces balance
// the loads on every free node; and under a small load it agrees with the linear model.
TEST(FemBody, CorotationalStaticEquilibrium) {
  const TetMesh mesh = make_tet_block(Vec3(0.1, 0.02, 0.02), {10, 2, 2});
  const auto clamped = nodes_where(mesh, [](const Vec3& p) { return p.x() < 1e-12; });
  const auto tip_load = [&](double total) {
    return traction_loads(
        mesh, [](const Vec3& p) { return p.x() > 0.1 - 1e-12; },
        Vec3(0.0, 0.0, -total / (0.02 * 0.02)));
  };
  // A heavy load: the tip drops by a third of the length, a large rotation.
  FemOptions o = options(kCorotational, kStatic);
  o.cg_relative_tolerance = 1e-10;
  FemBody heavy(mesh, {{0, material(10e3, 0.3)}}, clamped, o);
  const auto loads = tip_load(0.05);
  heavy.set_loads(loads);
  const FemStepStats stats = heavy.solve_static();
  EXPECT_TRUE(stats.converged);
  double drop = 0.0;
  for (const FemNodeForce& l : loads) {
    drop = std::max(drop, -heavy.displacement(l.node).z());
  }
  EXPECT_GT(drop, 0.02);
  std::vector<Vec3> elastic;
  heavy.elastic_forces(elastic);
  std::vector<Vec3> applied(mesh.node_count(), Vec3::Zero());
  for (const FemNodeForce& l : loads) {
    applied[l.node] += l.force_n;
  }
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    if (!heavy.is_fixed(static_cast<std::uint32_t>(i))) {
      EXPECT_LT((elastic[i] + applied[i]).norm(), 1e-7 * 0.05) << "node " << i;
    }
  }
  // Small load: the two models agree to O(rotation).
  FemBody small_co(mesh, {{0, material(10e3, 0.3)}}, clamped, o);
  FemBody small_lin(mesh, {{0, material(10e3, 0.3)}}, clamped, options(kLinear, kStatic));
  small_co.set_loads(tip_load(1e-6));
  small_lin.set_loads(tip_load(1e-6));
  small_co.solve_static();
  small_lin.solve_static();
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    const auto node = static_cast<std::uint32_t>(i);
    EXPECT_LT((small_co.displacement(node) - small_lin.displacement(node)).norm(),
              1e-3 * small_lin.displacement(node).norm() + 1e-15);
  }
}

// Backward Euler dissipates: a released, stretched body's total energy (elastic + kinetic) never
// increases from one step to the next, and the body comes to rest.
TEST(FemBody, BackwardEulerDissipatesEnergy) {
  const TetMesh mesh = make_tet_block(Vec3(0.02, 0.02, 0.06), {2, 2, 6});
  const auto bottom = nodes_where(mesh, [](const Vec3& p) { return p.z() < 1e-12; });
  std::vector<Vec3> stretched;
  for (const Vec3& p : mesh.nodes) {
    stretched.push_back(p + Vec3(0.02 * p.z(), 0.0, 0.1 * p.z()));
  }
  for (const FemElasticity model : {kLinear, kCorotational}) {
    SCOPED_TRACE(std::string(to_string(model)));
    FemOptions o = options(model, kEuler);
    o.cg_relative_tolerance = 1e-12;
    FemBody body(mesh, {{0, material(10e3, 0.3)}}, bottom, o);
    body.set_state(stretched);
    const double initial = body.elastic_energy_j() + body.kinetic_energy_j();
    ASSERT_GT(initial, 0.0);
    double previous = initial;
    for (int k = 0; k < 300; ++k) {
      body.step();
      const double total = body.elastic_energy_j() + body.kinetic_energy_j();
      // Linear: exactly monotone (round-off). Corotational: the rotations are held over a step
      // (the linearised implicit step), so a strict bound holds to the size of that lag only.
      const double slack = model == kLinear ? 1e-12 * initial : 1e-6 * initial;
      ASSERT_LE(total, previous + slack) << "step " << k;
      previous = total;
    }
    EXPECT_LT(previous, 1e-8 * initial);
    double fastest = 0.0;
    for (const Vec3& v : body.velocities()) {
      fastest = std::max(fastest, v.norm());
    }
    EXPECT_LT(fastest, 1e-4);  // released from ~0.1 m/s scales of motion
  }
}

// A block [-W, W]² × [-W, 0] (top face z = 0, fixed at its bottom) graded towards the origin:
// cube shells of the block's (2n)² × n cells, the innermost `uniform_shells` of equal width, then
// each `growth` times wider than the last; W such that the uniform core is `core_m` wide.
TetMesh graded_block(int n, int uniform_shells, double growth, double core_m) {
  const double s1 = static_cast<double>(uniform_shells) / n;
  const double beta = std::log(growth) * n;
  const double c = 1.0 / (s1 + (std::exp(beta * (1.0 - s1)) - 1.0) / beta);
  const double width = core_m / (c * s1);
  const auto shell = [&](double s) {
    return s <= s1 ? c * s : c * s1 + c / beta * (std::exp(beta * (s - s1)) - 1.0);
  };
  TetMesh mesh = make_tet_block(Vec3(2, 2, 1), {2 * n, 2 * n, n});
  for (Vec3& p : mesh.nodes) {
    Vec3 q = p - Vec3(1, 1, 1);
    const double s = q.lpNorm<Eigen::Infinity>();
    if (s > 0.0) {
      q *= shell(s) / s;
    }
    p = width * q;
  }
  return mesh;
}

struct HertzRun {
  double error = 0.0;     // F / F_Hertz − 1
  double exponent = 0.0;  // log(F(d)/F(d/2)) / log 2
  std::size_t tets = 0;
};

// With `exponent`, also the force at d/2, for the exponent.
HertzRun hertz_run(int n, double radius, double depth, bool exponent) {
  const double youngs = 10e3;
  const double poisson = 0.3;
  const double contact_radius = std::sqrt(radius * depth);
  const TetMesh mesh = graded_block(n, 2, 1.7, contact_radius);
  const double bottom = mesh.bounds().min().z();
  FemBody body(mesh, {{0, material(youngs, poisson)}},
               nodes_where(mesh, [&](const Vec3& p) { return p.z() < bottom + 1e-12; }),
               options(kLinear, kStatic));
  const double spacing = contact_radius / 2.0;       // the uniform core: 2 shells across a
  const double penalty = 1000.0 * youngs * spacing;  // node springs ≫ the tissue's E·h
  const double e_star = youngs / (1.0 - poisson * poisson);
  std::array<double, 2> force{};
  for (std::size_t k = exponent ? 0 : 1; k < 2; ++k) {
    const double d = k == 0 ? depth / 2.0 : depth;
    body.reset();
    const FemSphereContactResult r =
        body.solve_static_sphere_contact(Vec3(0.0, 0.0, radius - d), radius, penalty);
    EXPECT_TRUE(r.converged);
    EXPECT_GT(r.contact_nodes, 4u);
    // Frictionless and nearly symmetric (the tets' diagonals all lean one way): the force is
    // vertical to 1e-3.
    EXPECT_LT(r.force_on_sphere_n.head<2>().norm(), 1e-2 * r.force_on_sphere_n.z());
    force[k] = r.force_on_sphere_n.z();
  }
  HertzRun run;
  run.error = force[1] / (4.0 / 3.0 * e_star * std::sqrt(radius) * std::pow(depth, 1.5)) - 1.0;
  run.exponent = exponent ? std::log(force[1] / force[0]) / std::log(2.0) : 0.0;
  run.tets = mesh.tet_count();
  return run;
}

// Hertz: a rigid sphere (R = 10 mm) pressed d = 0.2 mm into a large block fixed at its bottom
// (ν = 0.3) gives F = 4/3·E*·√R·d^1.5, E* = E/(1 − ν²); the penalty contact's force and its
// exponent against that. The block must be large (W ≫ a) and fine at the contact (h ≪ a), so
// graded: cube shells from the contact outwards, two of width a/2, then each 1.7× wider. The
// FEM is too stiff by the domain's finite size and the linear tets' stiffness, both falling as
// the mesh grows. Measured (this grading; error, W/a):
//     5 184 tets: +29 % (W/a 8),     8 232: +24 % (13),  12 288: +21 % (23),
//    24 000 tets (q 1.6, 3 shells): +18 %,  41 472 (q 1.5): +13.5 %,  65 856 (q 1.45): +11.3 %,
// and +9.3 % at d = 0.1 mm on the last (W/a 76) - the 10 % the issue asks needs ~66k tets and
// 20 s, so it is the disabled test below; this one checks the trend and the exponent quickly.
TEST(FemBody, SphereIndentationApproachesHertz) {
  const HertzRun coarse = hertz_run(6, 0.01, 2e-4, false);
  const HertzRun fine = hertz_run(8, 0.01, 2e-4, true);
  EXPECT_GT(coarse.error, fine.error);
  EXPECT_GT(fine.error, 0.0);
  EXPECT_LT(fine.error, 0.25) << fine.tets << " tets";
  EXPECT_NEAR(fine.exponent, 1.5, 0.1);
}

// The corotational contact solve (rotations updated between the contact rounds) agrees with the
// linear one for a shallow indentation, and both push the sphere up by the same amount they
// press the body down: the reaction is the sum of the loads the body's support carries.
TEST(FemBody, CorotationalSphereContactAgreesWithLinear) {
  const TetMesh mesh = graded_block(5, 2, 1.5, 2e-3);
  const double bottom = mesh.bounds().min().z();
  const auto fixed = nodes_where(mesh, [&](const Vec3& p) { return p.z() < bottom + 1e-12; });
  std::array<double, 2> force{};
  for (const FemElasticity model : {kLinear, kCorotational}) {
    FemBody body(mesh, {{0, material(10e3, 0.3)}}, fixed, options(model, kStatic));
    const FemSphereContactResult r =
        body.solve_static_sphere_contact(Vec3(0.0, 0.0, 0.01 - 2e-4), 0.01, 1e4);
    EXPECT_TRUE(r.converged) << to_string(model);
    force[model == kLinear ? 0 : 1] = r.force_on_sphere_n.z();
    std::vector<Vec3> elastic;
    body.elastic_forces(elastic);
    Vec3 support = Vec3::Zero();
    for (const std::uint32_t n : fixed) {
      support += elastic[n];
    }
    // The elastic forces on the held nodes are what the support resists: the sphere's push.
    EXPECT_LT((support + r.force_on_sphere_n).norm(), 1e-4 * r.force_on_sphere_n.norm())
        << to_string(model);
  }
  EXPECT_GT(force[0], 0.0);
  EXPECT_NEAR(force[1], force[0], 0.02 * force[0]);
}

// The 10 % check of the issue, on 65 856 tets (about 10 s in a release build, the suite's slowest
// FEM test; linear tets and the block's finite size make it converge from above). Measured +9.3 %.
TEST(FemBody, SphereIndentationMatchesHertzWithin10Percent) {
  const double depth = 1e-4;
  const double radius = 0.01;
  const double youngs = 10e3;
  const double poisson = 0.3;
  const double contact_radius = std::sqrt(radius * depth);
  // 14 shells: 3 uniform ones over 1.0·a... as measured: the uniform core spans the contact.
  const TetMesh mesh = graded_block(14, 3, 1.45, 1.0 * std::sqrt(radius * 2e-4));
  const double bottom = mesh.bounds().min().z();
  FemBody body(mesh, {{0, material(youngs, poisson)}},
               nodes_where(mesh, [&](const Vec3& p) { return p.z() < bottom + 1e-12; }),
               options(kLinear, kStatic));
  const double spacing = 1.0 * std::sqrt(radius * 2e-4) / 3.0;
  const FemSphereContactResult r = body.solve_static_sphere_contact(
      Vec3(0.0, 0.0, radius - depth), radius, 1000.0 * youngs * spacing);
  const double hertz =
      4.0 / 3.0 * youngs / (1.0 - poisson * poisson) * std::sqrt(radius) * std::pow(depth, 1.5);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(std::abs(r.force_on_sphere_n.z() / hertz - 1.0), 0.10)
      << r.force_on_sphere_n.z() / hertz - 1.0 << " (a = " << contact_radius << " m)";
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FemBody, BadInputThrowsWithReason) {
  const TetMesh mesh = make_tet_block(Vec3::Constant(0.01), {1, 1, 1});
  const std::vector<std::uint32_t> bottom =
      nodes_where(mesh, [](const Vec3& p) { return p.z() < 1e-12; });
  const std::vector<FemRegionMaterial> good{{0, material(1e4, 0.3)}};
  const FemOptions o = options(kLinear, kStatic);
  const auto make = [&](TetMesh m, std::vector<FemRegionMaterial> mats,
                        std::vector<std::uint32_t> fixed) {
    return [=] { FemBody body(m, mats, fixed, o, "knee.msh"); };
  };
  std::string what = error_of(make(mesh, good, {}));
  EXPECT_NE(what.find("knee.msh"), std::string::npos) << what;
  EXPECT_NE(what.find("no fixed node"), std::string::npos) << what;

  what = error_of(make(mesh, {{0, material(0.0, 0.3)}}, bottom));
  EXPECT_NE(what.find("Young's modulus must be finite and > 0 Pa, got 0"), std::string::npos)
      << what;
  what = error_of(make(mesh, {{0, material(-5.0, 0.3)}}, bottom));
  EXPECT_NE(what.find("Young's modulus"), std::string::npos) << what;
  what = error_of(make(mesh, {{0, material(1e4, 0.5)}}, bottom));
  EXPECT_NE(what.find("Poisson ratio must be in [0, 0.5), got 0.5"), std::string::npos) << what;
  what = error_of(make(mesh, {{0, material(1e4, 0.3, -1.0)}}, bottom));
  EXPECT_NE(what.find("density"), std::string::npos) << what;
  FemRegionMaterial damped{0, material(1e4, 0.3)};
  damped.material.rayleigh_stiffness_s = -0.1;
  what = error_of(make(mesh, {damped}, bottom));
  EXPECT_NE(what.find("Rayleigh damping"), std::string::npos) << what;
  what =
      error_of(make(mesh, {{0, material(std::numeric_limits<double>::quiet_NaN(), 0.3)}}, bottom));
  EXPECT_NE(what.find("Young's modulus"), std::string::npos) << what;

  TetMesh regions = mesh;
  regions.regions.assign(mesh.tet_count(), 0);
  regions.regions[3] = 7;
  regions.regions[4] = 7;
  what = error_of(make(regions, good, bottom));
  EXPECT_NE(what.find("region 7 (element 3 is the first in it) has no material"), std::string::npos)
      << what;
  what = error_of(make(mesh, {{0, material(1e4, 0.3)}, {0, material(2e4, 0.3)}}, bottom));
  EXPECT_NE(what.find("already has"), std::string::npos) << what;

  what = error_of(make(mesh, good, {0, 999}));
  EXPECT_NE(what.find("fixed node 999 is out of range (the mesh has 8 nodes)"), std::string::npos)
      << what;
  // One fixed node holds no rotation: K is singular, and the factorisation says so.
  what = error_of(make(mesh, good, {0}));
  EXPECT_NE(what.find("not positive definite"), std::string::npos) << what;
  // An inverted element: validate_tet_mesh's message, with the element.
  TetMesh inverted = mesh;
  std::swap(inverted.tets[2][0], inverted.tets[2][1]);
  what = error_of(make(inverted, good, bottom));
  EXPECT_NE(what.find("element 2"), std::string::npos) << what;

  FemOptions bad_dt = o;
  bad_dt.dt_s = 0.0;
  EXPECT_THROW(FemBody(mesh, good, bottom, bad_dt), Error);

  FemBody body(mesh, good, bottom, o);
  std::vector<Vec3> wrong(body.fixed_nodes().size() + 1, Vec3::Zero());
  what = error_of([&] { body.set_fixed_positions(wrong); });
  EXPECT_NE(what.find("set_fixed_positions: expected 4 positions"), std::string::npos) << what;
  what = error_of([&] { body.set_state(std::vector<Vec3>(3, Vec3::Zero())); });
  EXPECT_NE(what.find("set_state"), std::string::npos) << what;
  what = error_of([&] { body.solve_static_sphere_contact(Vec3::Zero(), -1.0); });
  EXPECT_NE(what.find("radius"), std::string::npos) << what;
}

TEST(FemBody, NonFiniteLoadsAreRejectedAndCounted) {
  const TetMesh mesh = make_tet_block(Vec3(0.04, 0.01, 0.01), {4, 1, 1});
  const auto clamped = nodes_where(mesh, [](const Vec3& p) { return p.x() < 1e-12; });
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::uint32_t tip = static_cast<std::uint32_t>(mesh.node_count() - 1);
  FemBody clean(mesh, {{0, material(1e4, 0.3)}}, clamped, options(kCorotational, kStatic));
  FemBody dirty(mesh, {{0, material(1e4, 0.3)}}, clamped, options(kCorotational, kStatic));
  const std::vector<FemNodeForce> good{{tip, Vec3(0, 0, -1e-3)}};
  const std::vector<FemNodeForce> mixed{{tip, Vec3(nan, 0, 0)},
                                        {999, Vec3(0, 0, 1)},
                                        {tip, Vec3(0, 0, -1e-3)},
                                        {tip, Vec3(0, inf, 0)},
                                        {clamped[0], Vec3(0, 0, 5)}};  // on a fixed node: ignored
  clean.set_loads(good);
  dirty.set_loads(mixed);
  EXPECT_EQ(clean.rejected_loads(), 0u);
  EXPECT_EQ(dirty.rejected_loads(), 3u);
  clean.solve_static();
  dirty.solve_static();
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    EXPECT_TRUE(dirty.positions()[i].allFinite());
    EXPECT_EQ(dirty.positions()[i], clean.positions()[i]);
  }
  dirty.set_loads(mixed);
  EXPECT_EQ(dirty.rejected_loads(), 6u);  // counted since construction
}

// After the first step, step() (and the other per-step calls) allocate nothing: neither through
// operator new (the project's counter) nor through malloc (Eigen's temporaries).
TEST(FemBody, StepAllocatesNothing) {
  const TetMesh mesh = make_tet_block(Vec3(0.04, 0.04, 0.03), {4, 4, 3});
  const auto bottom = nodes_where(mesh, [](const Vec3& p) { return p.z() < 1e-12; });
  const auto top = nodes_where(mesh, [](const Vec3& p) { return p.z() > 0.03 - 1e-12; });
  std::vector<FemNodeForce> loads;
  for (const std::uint32_t n : top) {
    loads.push_back({n, Vec3(0.0, 1e-3, -5e-3)});
  }
  const std::vector<FemNodeWeight> point{{top[5], 0.5}, {top[6], 0.5}};
  for (const FemElasticity model : {kLinear, kCorotational}) {
    for (const FemIntegration integration : {kEuler, kStatic}) {
      SCOPED_TRACE(std::string(to_string(model)) + " " + std::string(to_string(integration)));
      FemBody body(mesh, {{0, material(5e3, 0.45)}}, bottom, options(model, integration));
      body.set_loads(loads);
      body.step();  // warm-up
      std::vector<Vec3> held;
      for (const std::uint32_t n : body.fixed_nodes()) {
        held.push_back(mesh.nodes[n] + Vec3(0.0, 0.0, 1e-4));
      }
      const Vec3* positions = body.positions().data();
      const long new_before = test::thread_allocation_count();
      const long malloc_before = fem_test_mallocs();
      double sink = 0.0;
      for (int k = 0; k < 20; ++k) {
        body.set_loads(loads);
        const FemStepStats stats = body.step();
        sink += stats.solve_ms + body.compliance_along(point, Vec3::UnitZ());
        if (k == 10) {
          body.set_fixed_positions(held);
        }
      }
      EXPECT_EQ(test::thread_allocation_count() - new_before, 0);
      EXPECT_EQ(fem_test_mallocs() - malloc_before, 0);
      EXPECT_EQ(body.positions().data(), positions);
      EXPECT_TRUE(std::isfinite(sink));
    }
  }
  // The counters work (otherwise the checks above could not fail).
  const long before = fem_test_mallocs();
  const long new_before = test::thread_allocation_count();
  std::vector<double> probe(100, 1.0);
  EXPECT_GT(test::thread_allocation_count(), new_before);
#ifdef HAPSIM_FEM_TEST_COUNTS_MALLOC
  EXPECT_GT(fem_test_mallocs(), before);
#endif
  EXPECT_EQ(probe.size(), 100u);
}

// Gravity on a column: the static settlement of a column under its own weight, against the
// one-dimensional answer for ν = 0: u(z) = ρ·g·(H·z − z²/2)/E at the top z = H: ρ·g·H²/(2E).
TEST(FemBody, ColumnUnderItsOwnWeight) {
  const double height = 0.05;
  const TetMesh mesh = make_tet_block(Vec3(0.01, 0.01, height), {1, 1, 10});
  FemOptions o = options(kLinear, kStatic);
  o.gravity_m_per_s2 = Vec3(0.0, 0.0, -9.81);
  FemBody body(mesh, {{0, material(2e3, 0.0, 1100.0)}},
               nodes_where(mesh, [](const Vec3& p) { return p.z() < 1e-12; }), o);
  EXPECT_NEAR(body.total_mass_kg(), 1100.0 * 0.01 * 0.01 * height, 1e-12);
  body.solve_static();
  const double expected = 1100.0 * 9.81 * height * height / (2.0 * 2e3);
  // The top face's mean settlement (one cell across: its four nodes differ by ±5 % as the tets'
  // diagonals shear the column a little; the mean cancels that).
  double top = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    if (mesh.nodes[i].z() > height - 1e-12) {
      top += -body.displacement(static_cast<std::uint32_t>(i)).z();
      ++count;
    }
  }
  EXPECT_NEAR(top / count, expected, 1e-3 * expected);
}

TEST(FemBody, ResetAndStatistics) {
  const TetMesh mesh = make_tet_block(Vec3(0.03, 0.03, 0.03), {3, 3, 3});
  const auto bottom = nodes_where(mesh, [](const Vec3& p) { return p.z() < 1e-12; });
  FemBody body(mesh, {{0, material(1e4, 0.3)}}, bottom, options(kCorotational, kEuler));
  EXPECT_EQ(body.unknowns(), 3 * (mesh.node_count() - bottom.size()));
  EXPECT_GT(body.factor_nonzeros(), body.unknowns());
  EXPECT_GT(body.factor_memory_bytes(), 8 * body.factor_nonzeros() / 2);
  EXPECT_GE(body.factorisation_ms(), 0.0);
  EXPECT_EQ(body.tet_count(), mesh.tet_count());
  EXPECT_EQ(to_string(kCorotational), "corotational");
  EXPECT_EQ(to_string(kEuler), "backward_euler");
  body.set_loads(std::vector<FemNodeForce>{
      {static_cast<std::uint32_t>(mesh.node_count() - 1), Vec3(0.0, 0.0, -0.05)}});
  for (int k = 0; k < 5; ++k) {
    const FemStepStats stats = body.step();
    EXPECT_TRUE(stats.converged);
    EXPECT_GT(stats.cg_iterations, 0);
  }
  EXPECT_GT(body.kinetic_energy_j(), 0.0);
  body.reset();
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    EXPECT_EQ(body.positions()[i], mesh.nodes[i]);
    EXPECT_EQ(body.velocities()[i], Vec3::Zero());
  }
  body.step();  // loads were cleared: nothing moves (but round-off: F = Ds·Dm⁻¹ ≈ I)
  for (std::size_t i = 0; i < mesh.node_count(); ++i) {
    EXPECT_LT((body.positions()[i] - mesh.nodes[i]).norm(), 1e-15);
  }
}

}  // namespace
}  // namespace hapsim
