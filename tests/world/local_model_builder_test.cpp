// The local model a World step leaves per tool, checked against the step itself one millimetre
// away (a rigid face's force is exactly linear) and against the series formula for a sheet.
#include "hapsim/world/local_model_builder.h"

#include "hapsim/deform/sheet_profile.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world.h"

#include "support/allocation_counter.h"
#include "support/body_fixtures.h"

#include <cmath>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

MaterialDescription penalty_material(double k, double max_penetration_m, double max_force_n) {
  MaterialDescription m;
  m.name = "tissue";
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = k;
  m.contact.max_penetration_m = max_penetration_m;
  m.contact.max_force_n = max_force_n;
  return m;
}

// A static box whose top face is z = 0, one point probe.
WorldDescription box_world() {
  WorldDescription w;
  w.name = "box";
  w.materials.push_back(penalty_material(500.0, 0.01, 4.0));
  w.passivity_damping_factor = 0.0;
  BodyDescription body;
  body.name = "block";
  body.X_world_body = Iso3(Eigen::Translation3d(0, 0, -0.02));
  SegmentDescription seg;
  seg.name = "block";
  seg.mesh = make_box(Vec3(0.05, 0.05, 0.02));
  body.segments.push_back(std::move(seg));
  w.bodies.push_back(std::move(body));
  w.tools.push_back(ToolDescription{"tip", 0.0, Vec3::Zero(), -1});
  return w;
}

DeviceInput at(const Vec3& p) {
  DeviceInput in;
  in.p_world = p;
  return in;
}

TEST(LocalModelBuilder, RigidFaceModelPredictsTheStepOneMillimetreDeeper) {
  World world(box_world());
  const LocalModelBuilder builder(world.model());
  world.step(at(Vec3(0.001, 0.0, -0.002)), 1e-3);
  std::array<LocalContactModel, 1> models;
  builder.build(world.state(), 7, 42, models);
  const LocalContactModel& m = models[0];
  EXPECT_TRUE(m.valid);
  EXPECT_EQ(m.sequence, 7u);
  EXPECT_EQ(m.device_sequence, 42u);
  EXPECT_NEAR(m.f0_world_n.z(), 1.0, 1e-9);
  EXPECT_NEAR(m.stiffness_n_per_m(2, 2), 500.0, 1e-9);  // rigid: the contact stiffness
  EXPECT_NEAR(m.stiffness_n_per_m.norm(), 500.0, 1e-9);
  EXPECT_NEAR(m.normal_world.z(), 1.0, 1e-12);

  const Vec3 deeper(0.001, 0.0, -0.003);
  World other(box_world());
  const double stepped_n = other.step(at(deeper), 1e-3).tools[0].force_world_n.z();
  EXPECT_NEAR(local_model_force(m, deeper, Vec3::Zero()).z(), stepped_n, 1e-9);
}

TEST(LocalModelBuilder, BuildingAllocatesNothing) {
  World world(box_world());
  const LocalModelBuilder builder(world.model());
  std::array<LocalContactModel, 1> models;
  world.step(at(Vec3(0.0, 0.0, -0.002)), 1e-3);
  const long before = test::allocation_count();
  for (std::uint64_t k = 1; k <= 100; ++k) {
    builder.build(world.state(), k, k, models);  // haptic path
  }
  EXPECT_EQ(test::allocation_count() - before, 0);
}

TEST(LocalModelBuilder, ASaturatedSpringHasNoStiffness) {
  World world(box_world());
  const LocalModelBuilder builder(world.model());
  world.step(at(Vec3(0.0, 0.0, -0.009)), 1e-3);  // 4.5 N by the spring, capped at 4 N
  std::array<LocalContactModel, 1> models;
  builder.build(world.state(), 1, 1, models);
  EXPECT_NEAR(models[0].f0_world_n.z(), 4.0, 1e-9);
  EXPECT_EQ(models[0].stiffness_n_per_m, Mat3::Zero());
  EXPECT_NEAR(models[0].max_normal_force_n, 4.0, 1e-9);
}

// The cap is where the contact stops pushing harder: its material's force cap (4 N) or, for a
// material that reaches its penetration limit first, k times the limit (500 N/m x 5 mm). A
// device a round trip deeper than x0 renders no more than the step there would.
TEST(LocalModelBuilder, CarriesTheForceTheContactSaturatesAt) {
  World world(box_world());
  const LocalModelBuilder builder(world.model());
  std::array<LocalContactModel, 1> models;
  world.step(at(Vec3(0.0, 0.0, -0.002)), 1e-3);  // 1 N, far from saturation
  builder.build(world.state(), 1, 1, models);
  EXPECT_NEAR(models[0].max_normal_force_n, 4.0, 1e-9);
  const Vec3 far_deeper(0.0, 0.0, -0.012);
  World other(box_world());
  const double stepped_n = other.step(at(far_deeper), 1e-3).tools[0].force_world_n.z();
  EXPECT_NEAR(stepped_n, 4.0, 1e-9);
  // The linear model alone says 6 N there; the cap is what the renderer holds it to.
  EXPECT_NEAR(local_model_force(models[0], far_deeper, Vec3::Zero()).z(), 6.0, 1e-9);

  WorldDescription limited = box_world();
  limited.materials[0] = penalty_material(500.0, 0.005, 4.0);
  World shallow(limited);
  const LocalModelBuilder shallow_builder(shallow.model());
  shallow.step(at(Vec3(0.0, 0.0, -0.002)), 1e-3);
  shallow_builder.build(shallow.state(), 1, 1, models);
  EXPECT_NEAR(models[0].max_normal_force_n, 2.5, 1e-9);

  World away(box_world());
  away.step(at(Vec3(0.0, 0.0, 0.01)), 1e-3);
  builder.build(away.state(), 1, 1, models);
  EXPECT_TRUE(std::isinf(models[0].max_normal_force_n));  // free space: no contact, no cap
}

TEST(LocalModelBuilder, FreeSpaceIsAValidZeroModel) {
  World world(box_world());
  const LocalModelBuilder builder(world.model());
  world.step(at(Vec3(0.0, 0.0, 0.01)), 1e-3);
  std::array<LocalContactModel, 1> models;
  builder.build(world.state(), 1, 1, models);
  EXPECT_TRUE(models[0].valid);
  EXPECT_EQ(models[0].f0_world_n, Vec3::Zero());
  EXPECT_EQ(models[0].stiffness_n_per_m, Mat3::Zero());
}

TEST(LocalModelBuilder, ASheetsComplianceIsInSeriesWithTheContact) {
  WorldDescription w;
  w.name = "sheet";
  w.materials.push_back(penalty_material(1000.0, 0.02, 10.0));
  w.passivity_damping_factor = 0.0;
  w.bodies.push_back(test::sheet_body(0));
  w.tools.push_back(ToolDescription{"tip", 0.0, Vec3::Zero(), -1});
  World world(std::move(w));
  const LocalModelBuilder builder(world.model());

  // The sheet under a contact: depth per newton at the contact point, z(0)/F (sheet_profile.h).
  const GaussianSheetParams p;
  const double compliance_m_per_n =
      (1.0 - std::exp(-(p.cutoff_radius_m * p.cutoff_radius_m) / (p.width_m * p.width_m))) /
      p.sensitivity_n_per_m;
  EXPECT_NEAR(builder.tissue_stiffness_n_per_m(0), 1.0 / compliance_m_per_n, 1e-6);

  const double expected_k = 1.0 / (1.0 / 1000.0 + compliance_m_per_n);
  // Come down onto the (two-sided) sheet from above, then hold 1 mm below its rest.
  for (const double z_m : {0.001, 0.0005, 0.0, -0.0005, -0.001, -0.001, -0.001, -0.001}) {
    world.step(at(Vec3(0.0, 0.0, z_m)), 1e-3);
  }
  std::array<LocalContactModel, 1> models;
  builder.build(world.state(), 1, 1, models);
  ASSERT_GT(models[0].f0_world_n.z(), 0.0);
  EXPECT_NEAR(models[0].stiffness_n_per_m(2, 2), expected_k, 1e-6 * expected_k);
}

}  // namespace
}  // namespace hapsim
