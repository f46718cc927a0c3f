// SPEC §8 in the world: a sheet gives way to the push the device actually rendered
// (World::set_rendered_push), not to the step's own force. A probe held 1 mm below a Gaussian
// sheet's rest settles where the sheet's depth is its Gaussian profile under the push that drives
// it: the step's own force without a rendered push, half of it when the device rendered half,
// none when it rendered none. Checked against the profile (sheet_profile.h).
#include "hapsim/deform/sheet_profile.h"
#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world.h"

#include "support/body_fixtures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

constexpr double kContactStiffness_n_per_m = 1000.0;

WorldDescription sheet_world() {
  WorldDescription w;
  w.name = "sheet";
  w.materials.push_back(test::penalty_material("tissue", kContactStiffness_n_per_m, 10.0, 0.0));
  w.passivity_damping_factor = 0.0;
  w.bodies.push_back(test::sheet_body(0));
  w.tools.push_back(ToolDescription{"tip", 0.0, Vec3::Zero(), -1});
  return w;
}

// The sheet's deepest node under a push of `push_n` at its centre: the Gaussian profile at the
// node nearest the centre (sheet_profile.h; the grid has no node at the centre itself).
double node_depth_m(const World& world, double push_n) {
  const VirtualSheet& sheet = *world.sheet(0);
  double nearest_m = sheet.side_m();
  for (int i = 0; i < sheet.nodes_per_side(); ++i) {
    nearest_m = std::min(nearest_m, std::abs(-0.5 * sheet.side_m() + i * sheet.spacing_m()));
  }
  return sheet.profile().depth_m(std::sqrt(2.0) * nearest_m, push_n);
}

DeviceInput at(double z_m) {
  DeviceInput in;
  in.p_world = Vec3(0.0, 0.0, z_m);
  return in;
}

struct Settled {
  double step_force_n = 0.0;
  double sheet_depth_m = 0.0;
  double depth_for_own_force_m = 0.0;  ///< the profile's depth under the step's own force
  double depth_for_rendered_m = 0.0;   ///< and under the push the device was said to render
};

// Comes down onto the sheet and holds 1 mm below its rest for 2 s; before every step the device
// is said to have rendered `share` of the previous step's force (NaN: nothing said).
Settled hold(double share) {
  World world(sheet_world());
  double force_n = 0.0;
  for (const double z_m : {0.001, 0.0005, 0.0}) {
    force_n = world.step(at(z_m), 1e-3).tools[0].force_world_n.norm();
  }
  double rendered_n = 0.0;
  for (int k = 0; k < 2000; ++k) {
    rendered_n = share * force_n;
    const std::array<double, 1> rendered{rendered_n};
    world.set_rendered_push(rendered);
    force_n = world.step(at(-0.001), 1e-3).tools[0].force_world_n.norm();
  }
  return {force_n, world.last_result().sheet_depth_m[0], node_depth_m(world, force_n),
          std::isnan(share) ? 0.0 : node_depth_m(world, rendered_n)};
}

TEST(SheetRenderedPush, TheSheetGivesWayToWhatTheDeviceRendered) {
  // Nothing said: the sheet carries the step's own force.
  const Settled own = hold(std::numeric_limits<double>::quiet_NaN());
  ASSERT_GT(own.step_force_n, 0.1);
  EXPECT_NEAR(own.sheet_depth_m, own.depth_for_own_force_m, 1e-6 * own.sheet_depth_m);

  // Half rendered: the sheet carries that half, so it sits shallower, and the contact spring,
  // less relieved, pushes harder than when the sheet gave way to all of it.
  const Settled half = hold(0.5);
  EXPECT_NEAR(half.sheet_depth_m, half.depth_for_rendered_m, 1e-6 * own.sheet_depth_m);
  EXPECT_NEAR(half.sheet_depth_m, 0.5 * half.depth_for_own_force_m, 1e-6 * own.sheet_depth_m);
  EXPECT_LT(half.sheet_depth_m, own.sheet_depth_m);
  EXPECT_GT(half.step_force_n, own.step_force_n);

  // Nothing rendered: the sheet stays at rest and the contact spring alone answers, k·1 mm.
  const Settled none = hold(0.0);
  EXPECT_EQ(none.sheet_depth_m, 0.0);
  EXPECT_NEAR(none.step_force_n, kContactStiffness_n_per_m * 0.001, 1e-9);
}

TEST(SheetRenderedPush, ARenderedPushDrivesOneStepOnly) {
  World world(sheet_world());
  for (const double z_m : {0.001, 0.0005, 0.0, -0.001}) {
    (void)world.step(at(z_m), 1e-3);
  }
  const std::array<double, 1> nothing{0.0};
  world.set_rendered_push(nothing);
  (void)world.step(at(-0.001), 1e-3);
  EXPECT_EQ(world.last_result().sheet_depth_m[0], 0.0);
  (void)world.step(at(-0.001), 1e-3);  // nothing said: the step's own force again
  EXPECT_GT(world.last_result().sheet_depth_m[0], 0.0);
}

}  // namespace
}  // namespace hapsim
