// A FEM body in the world (world/fem_coupling.h, stage_fem_contacts.cpp): the haptic cycle
// renders the local contact model the FEM hands it, and the FEM takes what was rendered as its
// load. Checked against an independent quasi-static solve of the same FEM body under the same
// patch load (the contact spring in series with the tissue: F = k_c·(d0 − u(F))), against the
// schedule (an update adopted exactly one FEM period after its launch), and for determinism
// (deferred and in-step updates give the same bits) and allocation (none in the step).
#include "hapsim/deform/fem_body.h"
#include "hapsim/geometry/tet_mesh.h"
#include "hapsim/world/fem_coupling.h"
#include "hapsim/world/world.h"
#include "hapsim/world/world_step.h"

#include "support/allocation_counter.h"
#include "support/body_fixtures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace hapsim {
namespace {

constexpr double kContactStiffness_n_per_m = 2000.0;
constexpr double kToolRadius_m = 0.005;
constexpr double kTopZ_m = 0.02;  // the block is 40 × 40 × 20 mm, its bottom at z = 0

std::shared_ptr<FemBodyDescription> block_volume(FemElasticity elasticity,
                                                 FemIntegration integration) {
  auto d = std::make_shared<FemBodyDescription>();
  d->tets = make_tet_block(Vec3(0.04, 0.04, 0.02), {8, 8, 4});
  d->tets.transform(Iso3(Eigen::Translation3d(-0.02, -0.02, 0.0)));
  FemMaterial m;
  m.youngs_modulus_pa = 20e3;
  m.poisson_ratio = 0.4;
  m.rayleigh_mass_per_s = 5.0;
  m.rayleigh_stiffness_s = 0.01;
  d->materials = {{0, m}};
  d->options.elasticity = elasticity;
  d->options.integration = integration;
  d->options.dt_s = 0.01;
  d->fixed_below_z_m = 1e-6;
  d->contact_patch_radius_m = 0.006;
  d->source = "test block";
  return d;
}

WorldDescription block_world(FemElasticity elasticity = FemElasticity::kLinear,
                             FemIntegration integration = FemIntegration::kQuasiStatic) {
  WorldDescription w;
  w.name = "fem block";
  w.materials.push_back(test::penalty_material("soft", kContactStiffness_n_per_m, 20.0, 0.0));
  w.materials.back().contact.max_penetration_m = 0.03;
  auto volume = block_volume(elasticity, integration);
  BodyDescription b;
  b.name = "block";
  b.kind = BodyKind::kDeformable;
  b.deformation = BodyDeformation::kFem;
  SegmentDescription s;
  s.name = "block";
  s.material = 0;
  s.mesh = tet_boundary(volume->tets).surface;
  b.segments.push_back(std::move(s));
  b.fem = volume;
  w.bodies.push_back(std::move(b));
  w.tools.push_back(ToolDescription{"tip", kToolRadius_m, Vec3::Zero(), -1});
  return w;
}

// The probe's centre `depth_m` below where its sphere first touches the top's centre.
DeviceInput pressed(double depth_m) {
  return test::probe_at(Vec3(0.0, 0.0, kTopZ_m + kToolRadius_m - depth_m));
}

TEST(FemWorld, AHeldProbeSettlesWhereTheContactSpringMeetsTheTissue) {
  World world(block_world());
  const double depth_m = 0.004;
  for (int k = 0; k < 100; ++k) {  // come down over 0.1 s
    world.step(pressed(depth_m * (k + 1) / 100.0), 1e-3);
  }
  double force_n = 0.0;
  for (int k = 0; k < 1500; ++k) {
    force_n = world.step(pressed(depth_m), 1e-3).tools[0].force_world_n.z();
  }
  ASSERT_GT(force_n, 0.05);
  // Independently: the same FEM body under the same load, spread over the patch the coupling
  // chose (the surface nodes around the contact's material point, weighted 1 − (r/R)²), solved
  // statically by a FemBody of its own. The patch's displacement u(F) along the normal must
  // close the loop F = k_c·(d0 − u(F)): the contact spring in series with the tissue.
  const FemBodyDescription& d = *world.description().bodies[0].fem;
  std::vector<FemNodeWeight> patch = world.fem()->contact_patch(0, 0);
  ASSERT_FALSE(patch.empty());
  double sum = 0.0;
  for (const FemNodeWeight& w : patch) {
    sum += w.weight;
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  std::vector<std::uint32_t> fixed;
  for (std::size_t i = 0; i < d.tets.nodes.size(); ++i) {
    if (d.tets.nodes[i].z() <= 1e-6) {
      fixed.push_back(static_cast<std::uint32_t>(i));
    }
  }
  FemBody reference(d.tets, d.materials, fixed, d.options);
  std::vector<FemNodeForce> loads;
  for (const FemNodeWeight& w : patch) {
    loads.push_back({w.node, Vec3(0.0, 0.0, -force_n * w.weight)});
  }
  reference.set_loads(loads);
  reference.solve_static();
  double sink_m = 0.0;
  for (const FemNodeWeight& w : patch) {
    sink_m -= w.weight * reference.displacement(w.node).z();
  }
  ASSERT_GT(sink_m, 0.0);
  EXPECT_NEAR(force_n, kContactStiffness_n_per_m * (depth_m - sink_m), 0.03 * force_n)
      << "sink " << sink_m * 1e3 << " mm";
  // And softer than the contact spring alone: the tissue gave way.
  EXPECT_LT(force_n, 0.9 * kContactStiffness_n_per_m * depth_m);
}

// Strain stiffening (Zheng & Mak's E(ε) = E₀ + E₁·ε, ε = δ/h): the block held 4 mm deep with
// E₁ = 10·E₀ settles where the contact spring meets a tissue that indents as
// F = k₁·δ·(1 + κ·δ), κ = (E₁/E₀)/h, h each patch node's distance to the table (20 mm under the
// top's centre); checked against the same independent static solve as above (linear: δ = c·F
// for the linear tissue, so the stiffened δ solves κ·δ² + δ − c·F = 0), and harder than the
// linear block at the same depth.
TEST(FemWorld, AStiffeningTissueSettlesOnItsQuadraticLoadIndentation) {
  const double depth_m = 0.004;
  const auto hold = [&](World& world) {
    for (int k = 0; k < 100; ++k) {
      world.step(pressed(depth_m * (k + 1) / 100.0), 1e-3);
    }
    double force_n = 0.0;
    for (int k = 0; k < 1500; ++k) {
      force_n = world.step(pressed(depth_m), 1e-3).tools[0].force_world_n.z();
    }
    return force_n;
  };
  World linear(block_world());
  const double linear_n = hold(linear);
  WorldDescription wd = block_world();
  auto volume = std::make_shared<FemBodyDescription>(*wd.bodies[0].fem);
  const double ratio = 10.0;
  volume->materials[0].material.nonlinear_modulus_pa =
      ratio * volume->materials[0].material.youngs_modulus_pa;
  wd.bodies[0].fem = volume;
  World world(wd);
  const double force_n = hold(world);
  ASSERT_GT(force_n, 0.05);
  const FemBodyDescription& d = *volume;
  const std::vector<FemNodeWeight> patch = world.fem()->contact_patch(0, 0);
  ASSERT_FALSE(patch.empty());
  std::vector<std::uint32_t> fixed;
  for (std::size_t i = 0; i < d.tets.nodes.size(); ++i) {
    if (d.tets.nodes[i].z() <= 1e-6) {
      fixed.push_back(static_cast<std::uint32_t>(i));
    }
  }
  double kappa_per_m = 0.0;
  for (const FemNodeWeight& w : patch) {
    double nearest_m = kInf;
    for (const std::uint32_t n : fixed) {
      nearest_m = std::min(nearest_m, (d.tets.nodes[n] - d.tets.nodes[w.node]).norm());
    }
    kappa_per_m += w.weight * ratio / nearest_m;
  }
  EXPECT_NEAR(kappa_per_m, ratio / 0.02, 0.1 * ratio / 0.02);  // h ≈ the block's 20 mm
  // The linear tissue's compliance at the patch, c (m/N), from a static solve under 1 N.
  FemBody reference(d.tets, d.materials, fixed, d.options);
  std::vector<FemNodeForce> loads;
  for (const FemNodeWeight& w : patch) {
    loads.push_back({w.node, Vec3(0.0, 0.0, -w.weight)});
  }
  reference.set_loads(loads);
  reference.solve_static();
  double c_m_per_n = 0.0;
  for (const FemNodeWeight& w : patch) {
    c_m_per_n -= w.weight * reference.displacement(w.node).z();
  }
  ASSERT_GT(c_m_per_n, 0.0);
  const double delta_m =
      (-1.0 + std::sqrt(1.0 + 4.0 * kappa_per_m * c_m_per_n * force_n)) / (2.0 * kappa_per_m);
  EXPECT_NEAR(force_n, kContactStiffness_n_per_m * (depth_m - delta_m), 0.03 * force_n)
      << "indentation " << delta_m * 1e3 << " mm, linear " << c_m_per_n * force_n * 1e3 << " mm";
  EXPECT_GT(force_n, 1.1 * linear_n) << "linear " << linear_n << " N";
}

// Held still 7 mm deep (the tissue gives ~6 mm), off the top's centre, on the flat top: the force
// settles along the top's normal, steady. Taking the load's direction from the dent's own
// deformed normal once fed the dent's slope back into the load: the probe then rang or wandered
// sideways (±1 N at 6 mm, quasi-static; 0.4 N drifting at 8 mm, backward Euler); and the
// corotational quasi-static body, whose squeezed tissue answers softer than compliance_along
// says, flipped between 1.4 and 2.5 N every update until the coupling measured the softening.
TEST(FemWorld, AProbeHeldDeepInTheDentFeelsASteadyForceAlongTheNormal) {
  for (const FemElasticity elasticity : {FemElasticity::kLinear, FemElasticity::kCorotational}) {
    for (const FemIntegration integration :
         {FemIntegration::kQuasiStatic, FemIntegration::kBackwardEuler}) {
      World world(block_world(elasticity, integration));
      world.set_fem_deferred(true);
      const Vec3 above(-0.006, 0.004, kTopZ_m + kToolRadius_m);
      const double depth_m = 0.007;
      double min_z = 1e9;
      double max_z = 0.0;
      double max_lateral = 0.0;
      for (int k = 0; k < 3000; ++k) {  // down over 0.4 s, then held 2.6 s
        DeviceInput in =
            test::probe_at(above - Vec3::UnitZ() * depth_m * std::min(1.0, (k + 1) / 400.0));
        in.time_s = k * 1e-3;
        const Vec3 f = world.step(in, 1e-3).command.force_world_n;
        world.advance_fem();
        ASSERT_TRUE(f.allFinite());
        if (k >= 2000) {  // the last second
          min_z = std::min(min_z, f.z());
          max_z = std::max(max_z, f.z());
          max_lateral = std::max(max_lateral, f.head<2>().norm());
        }
      }
      const std::string what =
          std::string(to_string(elasticity)) + ", " + std::string(to_string(integration));
      EXPECT_GT(min_z, 0.5) << what;  // pressed: k_series · 7 mm
      EXPECT_LT(max_z - min_z, 1e-3 * max_z) << what;
      EXPECT_LT(max_lateral, 1e-6) << what;
    }
  }
}

// The damping a FEM contact is rendered with: Colgate's floor factor·k·T on the stiffness it
// renders (the contact spring in series with the tissue, ~10x softer here than the spring
// alone), with T the haptic period for a quasi-static tissue (the model's spring is its
// equilibrium) and the FEM's period for a dynamic one (its motion reaches the hand sampled then).
TEST(FemWorld, AContactIsDampedForTheStiffnessItRendersAndTheFemsSampling) {
  for (const FemIntegration integration :
       {FemIntegration::kQuasiStatic, FemIntegration::kBackwardEuler}) {
    World world(block_world(FemElasticity::kLinear, integration));
    for (int k = 0; k < 200; ++k) {
      world.step(pressed(0.004 * std::min(1.0, (k + 1) / 100.0)), 1e-3);
    }
    const LocalContactModel& m = world.state().fem_contacts[0].model;
    ASSERT_TRUE(m.valid);
    const double k_series = m.normal_world.dot(m.stiffness_n_per_m * m.normal_world);
    ASSERT_LT(k_series, 0.5 * kContactStiffness_n_per_m);  // the tissue gives
    const ContactMaterial& material = world.state().material_contact[0];
    ASSERT_EQ(material.damping_n_s_per_m, 0.0);
    const double b = fem_contact_damping_n_s_per_m(world.model(), material, m, 1e-3);
    const double fem_period_s = integration == FemIntegration::kQuasiStatic ? 1e-3 : 0.01;
    EXPECT_NEAR(b, k_series * fem_period_s, 1e-9 * b) << to_string(integration);
    // A material damped more than the floor keeps its own.
    ContactMaterial damped = material;
    damped.damping_n_s_per_m = 50.0;
    EXPECT_EQ(fem_contact_damping_n_s_per_m(world.model(), damped, m, 1e-3), 50.0);
  }
}

TEST(FemWorld, TheSurfaceDentsUnderTheProbeAndNotFarAway) {
  World world(block_world(FemElasticity::kCorotational, FemIntegration::kBackwardEuler));
  for (int k = 0; k < 1000; ++k) {
    world.step(pressed(std::min(0.006, 0.006 * (k + 1) / 300.0)), 1e-3);
  }
  const TriangleMesh& surface = world.surface(0, 0);
  double centre_z = kInf;
  double corner_z = 0.0;
  for (const Vec3& v : surface.vertices) {
    if (std::abs(v.x()) < 2e-3 && std::abs(v.y()) < 2e-3 && v.z() > 0.01) {
      centre_z = std::min(centre_z, v.z());
    }
    if (v.x() > 0.019 && v.y() > 0.019 && v.z() > 0.019) {
      corner_z = v.z();
    }
  }
  EXPECT_LT(centre_z, kTopZ_m - 0.001) << "the top's centre sank by under 1 mm";
  EXPECT_NEAR(corner_z, kTopZ_m, 0.5e-3) << "a far corner moved";
}

TEST(FemWorld, AnUpdateIsAdoptedExactlyOneFemPeriodAfterItsLaunch) {
  World world(block_world());
  const double depth_m = 0.003;
  std::vector<double> force_n;
  for (int k = 0; k < 300; ++k) {
    force_n.push_back(world.step(pressed(depth_m), 1e-3).tools[0].force_world_n.z());
  }
  ASSERT_EQ(world.fem()->period_steps(), 10u);
  // The probe holds still. A new model is adopted at steps 20, 30, ... (launched at 10, 20, ...;
  // the step index counts from 1, force_n from 0) and blended in over one period: between two
  // adoptions the force is a straight ramp from the old model's to the new one's, so it bends
  // only at an adoption step, and it is continuous there (no step: the old model's force is the
  // ramp's start).
  int bends = 0;
  for (std::size_t k = 1; k + 1 < force_n.size(); ++k) {
    const double second_difference = force_n[k + 1] - 2.0 * force_n[k] + force_n[k - 1];
    if (std::abs(second_difference) > 1e-9 * (1.0 + std::abs(force_n[k]))) {
      ++bends;
      EXPECT_EQ((k + 1) % 10, 0u) << "the force bent at step " << k + 1;
    }
  }
  EXPECT_GT(bends, 5);
  // No step bigger than a tenth of the largest force (the first model's, ramped in from none
  // over ten steps): a ramp, never a jump.
  double largest_step_n = 0.0;
  double largest_n = 0.0;
  for (std::size_t k = 1; k < force_n.size(); ++k) {
    largest_step_n = std::max(largest_step_n, std::abs(force_n[k] - force_n[k - 1]));
    largest_n = std::max(largest_n, std::abs(force_n[k]));
  }
  EXPECT_GT(largest_n, 0.5);
  EXPECT_LE(largest_step_n, 0.1 * largest_n + 1e-9);
  EXPECT_EQ(world.fem()->late_adopted(), 0u);
}

TEST(FemWorld, DeferredUpdatesGiveTheSameBitsAsUpdatesInTheStep) {
  World in_step(block_world(FemElasticity::kCorotational, FemIntegration::kBackwardEuler));
  World deferred(block_world(FemElasticity::kCorotational, FemIntegration::kBackwardEuler));
  deferred.set_fem_deferred(true);
  for (int k = 0; k < 800; ++k) {
    // Down, then sliding sideways at 20 mm/s while pressed.
    const double t = k * 1e-3;
    const DeviceInput in =
        test::probe_at(Vec3(std::max(0.0, t - 0.3) * 0.02, 0.0,
                            kTopZ_m + kToolRadius_m - std::min(t, 0.3) / 0.3 * 0.005));
    const Vec3 a = in_step.step(in, 1e-3).tools[0].force_world_n;
    const Vec3 b = deferred.step(in, 1e-3).tools[0].force_world_n;
    deferred.advance_fem();
    ASSERT_EQ(a.x(), b.x()) << "step " << k;
    ASSERT_EQ(a.y(), b.y()) << "step " << k;
    ASSERT_EQ(a.z(), b.z()) << "step " << k;
  }
  EXPECT_GT(in_step.last_result().tools[0].force_world_n.z(), 0.1);
}

TEST(FemWorld, TheStepAllocatesNothing) {
  World world(block_world(FemElasticity::kCorotational, FemIntegration::kBackwardEuler));
  world.set_fem_deferred(true);
  for (int k = 0; k < 100; ++k) {
    world.step(pressed(0.004 * k / 100.0), 1e-3);
    world.advance_fem();
  }
  long allocations = 0;
  for (int k = 0; k < 200; ++k) {
    const long before = test::allocation_count();
    world.step(pressed(0.004), 1e-3);
    allocations += test::allocation_count() - before;
    world.advance_fem();  // the FEM side may allocate (not the haptic path)
  }
  EXPECT_EQ(allocations, 0);
}

TEST(FemWorld, AToolFarAwayFeelsNothingAndLoadsNothing) {
  World world(block_world());
  for (int k = 0; k < 200; ++k) {
    const StepResult& r = world.step(test::probe_at(Vec3(0.0, 0.0, 0.1)), 1e-3);
    EXPECT_EQ(r.tools[0].force_world_n.norm(), 0.0);
  }
  EXPECT_EQ(world.fem()->body(0).displacement(0).norm(), 0.0);
}

}  // namespace
}  // namespace hapsim
