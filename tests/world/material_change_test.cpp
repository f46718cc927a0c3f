// World::set_material_contact: a live stiffness change takes effect at the next step (Hooke's
// law on a penalty box), and values a step cannot use are refused without changing anything.
#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

#include <limits>

namespace hapsim {
namespace {

World box_world() {
  WorldDescription w;
  MaterialDescription m;
  m.name = "muscle";
  m.response = ContactResponse::kPenalty;
  m.contact.stiffness_n_per_m = 400.0;
  m.contact.max_penetration_m = 0.02;
  m.contact.max_force_n = 50.0;
  w.materials.push_back(m);
  BodyDescription b;
  b.name = "block";
  SegmentDescription s;
  s.name = "box";
  s.mesh = make_box(Vec3(0.05, 0.05, 0.05));  // top face at z = 0.05
  b.segments.push_back(std::move(s));
  w.bodies.push_back(std::move(b));
  ToolDescription t;
  t.name = "tip";
  t.radius_m = 0.0;
  w.tools.push_back(t);
  w.passivity_damping_factor = 0.0;
  return World(std::move(w));
}

double force_at_depth(World& world, double depth_m) {
  DeviceInput in;
  in.p_world = Vec3(0.0, 0.0, 0.05 - depth_m);
  world.step(in, 0.001);  // the same position twice: no velocity, no damping force
  return world.step(in, 0.001).command.force_world_n.z();
}

TEST(MaterialChange, StiffnessChangeTakesEffectAtTheNextStep) {
  World world = box_world();
  EXPECT_NEAR(force_at_depth(world, 0.005), 400.0 * 0.005, 1e-9);
  ContactMaterial c = world.description().materials[0].contact;
  c.stiffness_n_per_m = 1000.0;
  ASSERT_TRUE(world.set_material_contact(0, c));
  EXPECT_EQ(world.material_contact(0).stiffness_n_per_m, 1000.0);
  EXPECT_EQ(world.description().materials[0].contact.stiffness_n_per_m, 400.0);  // as described
  EXPECT_NEAR(force_at_depth(world, 0.005), 1000.0 * 0.005, 1e-9);
  c.max_force_n = 3.0;  // the cap too
  ASSERT_TRUE(world.set_material_contact(0, c));
  EXPECT_NEAR(force_at_depth(world, 0.005), 3.0, 1e-9);
}

TEST(MaterialChange, UnusableValuesAreRefusedAndChangeNothing) {
  World world = box_world();
  const ContactMaterial good = world.description().materials[0].contact;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& edit : std::vector<void (*)(ContactMaterial&, double)>{
           [](ContactMaterial&c, double v) { c.stiffness_n_per_m = v; },
           [](ContactMaterial&c, double v) { c.max_force_n = v; },
           [](ContactMaterial&c, double v) { c.max_penetration_m = v; }}) {
    for (const double bad : {0.0, -1.0, nan, std::numeric_limits<double>::infinity()}) {
      ContactMaterial c = good;
      edit(c, bad);
      EXPECT_FALSE(world.set_material_contact(0, c)) << bad;
    }
  }
  ContactMaterial c = good;
  c.damping_n_s_per_m = -1.0;
  EXPECT_FALSE(world.set_material_contact(0, c));
  c = good;
  c.static_friction = 0.1;
  c.dynamic_friction = 0.2;  // slipping above sticking
  EXPECT_FALSE(world.set_material_contact(0, c));
  EXPECT_FALSE(world.set_material_contact(3, good));               // no such material
  EXPECT_NEAR(force_at_depth(world, 0.005), 400.0 * 0.005, 1e-9);  // unchanged
}

}  // namespace
}  // namespace hapsim
