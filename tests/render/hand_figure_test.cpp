// The glove hand as a figure: its capsules checked against the hand's own kinematics, not stored
// pictures — each finger's last capsule ends at the fingertip HandModel::fingertips_world gives
// (where the tool sits), the angle between the middle and distal phalanges is the DIP angle the
// coupling makes of the PIP reading (DIP = ratio · PIP), the palm reaches every finger's MCP; a
// reading that does not put the fingertips at the tools draws no hand; and in a picture, the
// hand's colour is drawn where a finger projects.
#include "hapsim/render/hand_figure.h"

#include "hapsim/render/world_scene.h"
#include "hapsim/runtime/world_snapshot.h"
#include "hapsim/scene/scene_device.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"
#include "render/gl_test_context.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace hapsim {
namespace {

GloveReading bent_reading() {
  GloveReading r;
  r.X_world_hand = Eigen::Translation3d(0.1, -0.2, 0.3) *
                   Eigen::AngleAxisd(0.4, Vec3(1.0, 2.0, 0.5).normalized());
  for (int f = 0; f < kHandFingers; ++f) {
    const double k = 0.1 * f;
    r.angles_rad[static_cast<std::size_t>(f)] = {0.05 - 0.03 * f, 0.3 + k, 0.6 + 2.0 * k};
  }
  return r;
}

double angle_between(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(HandFigure, FingertipsSitWhereTheHandModelPutsThemAndTheDipFollowsThePip) {
  const HandModel hand;
  const GloveReading reading = bent_reading();
  std::vector<RenderCapsule> capsules;
  add_hand_figure(hand, reading, kHandColour, capsules);
  // Three phalanges per finger first, in finger order, then the palm.
  ASSERT_GE(capsules.size(), static_cast<std::size_t>(3 * kHandFingers + 4));
  const auto tips = hand.fingertips_world(reading);
  for (int f = 0; f < kHandFingers; ++f) {
    const auto base = static_cast<std::size_t>(3 * f);
    const RenderCapsule& proximal = capsules[base];
    const RenderCapsule& middle = capsules[base + 1];
    const RenderCapsule& distal = capsules[base + 2];
    EXPECT_LT((distal.b_world - tips[static_cast<std::size_t>(f)]).norm(), 1e-12) << "finger " << f;
    // Joined end to end.
    EXPECT_LT((proximal.b_world - middle.a_world).norm(), 1e-12);
    EXPECT_LT((middle.b_world - distal.a_world).norm(), 1e-12);
    // Lengths are the phalanges'.
    const FingerGeometry& g = hand.geometry().fingers[static_cast<std::size_t>(f)];
    EXPECT_NEAR((middle.b_world - middle.a_world).norm(), g.phalanx_m[1], 1e-12);
    EXPECT_NEAR((distal.b_world - distal.a_world).norm(), g.phalanx_m[2], 1e-12);
    // The bends: PIP between proximal and middle, DIP = ratio · PIP between middle and distal.
    const double pip = reading.angles_rad[static_cast<std::size_t>(f)][2];
    EXPECT_NEAR(angle_between(proximal.b_world - proximal.a_world, middle.b_world - middle.a_world),
                pip, 1e-9)
        << "finger " << f;
    EXPECT_NEAR(angle_between(middle.b_world - middle.a_world, distal.b_world - distal.a_world),
                hand.geometry().dip_per_pip * pip, 1e-9)
        << "finger " << f;
    // The fingertip's capsule is as thick as the fingertip sphere.
    EXPECT_DOUBLE_EQ(distal.radius_m, g.tip_radius_m);
  }
  // The palm reaches each finger's MCP (a palm capsule ends there).
  for (int f = 0; f < kHandFingers; ++f) {
    const Vec3 mcp =
        reading.X_world_hand * hand.geometry().fingers[static_cast<std::size_t>(f)].mcp_hand;
    bool reached = false;
    for (std::size_t c = 3 * kHandFingers; c < capsules.size(); ++c) {
      reached |= (capsules[c].b_world - mcp).norm() < 1e-12;
    }
    EXPECT_TRUE(reached) << "finger " << f;
  }
}

TEST(HandFigure, KneeHandSceneDrawsTheHandAtItsTools) {
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_hand_procedural.json");
  World world(scene.world);
  auto device = make_scene_device(scene, world);
  // 1.6 s in: the hand has come to the knee and the fingers press.
  for (int i = 0; i < 1600; ++i) {
    world.step(device->read(i * scene.run.dt_s), scene.run.dt_s);
  }
  WorldScene view(world);
  view.update_from_world(world);
  const auto& capsules = view.scene().capsules;
  ASSERT_GE(capsules.size(), static_cast<std::size_t>(3 * kHandFingers));
  for (std::size_t t = 0; t < world.description().tools.size(); ++t) {
    const int f = world.description().tools[t].finger;
    EXPECT_LT((capsules[static_cast<std::size_t>(3 * f + 2)].b_world -
               world.last_result().tools[t].p_world)
                  .norm(),
              1e-12)
        << world.description().tools[t].name;
  }
  // A view that carries the tools but not this reading (a served world's): no hand, since it
  // would not reach the tools.
  {
    WorldScene served(world);
    WorldSnapshot snapshot = make_world_snapshot(world);
    snapshot.tools[0].p_world += Vec3(0.01, 0.0, 0.0);
    served.update(snapshot);
    EXPECT_TRUE(served.scene().capsules.empty());
  }
  // In a picture: the hand's colour where the middle finger's PIP projects.
  auto gl = test::make_test_context(320, 240);
  if (!gl.context) {
    GTEST_SKIP() << "no offscreen GL context: " << gl.why_not;
  }
  Renderer renderer;
  OrbitCamera cam;
  cam.target_world = capsules[7].a_world;  // middle finger's PIP
  cam.yaw_rad = 1.95;
  cam.pitch_rad = 0.3;
  cam.distance_m = 0.3;
  view.scene().spheres.clear();
  renderer.draw(view.scene(), cam, 320, 240);
  const auto image = gl.context->read_rgba();
  const test::Pixel p = test::pixel_at(image, 320, 160, 120);
  // Lit purple: blue above green, red above green.
  EXPECT_GT(p.b, p.g + 20) << p.r << " " << p.g << " " << p.b;
  EXPECT_GT(p.r, p.g) << p.r << " " << p.g << " " << p.b;
}

}  // namespace
}  // namespace hapsim
