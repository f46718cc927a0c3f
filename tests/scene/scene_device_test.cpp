// Aiming a scene's palpation: the target lands on the first surface met along `from` (skin over
// bone, like a finger would), exactly on analytic shapes, whatever contact method the body uses;
// the planned press reaches that surface plus the depth.
#include "hapsim/script/palpation_aim.h"
#include "hapsim/script/scene_palpation_plan.h"

#include "hapsim/core/error.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

namespace hapsim {
namespace {

MaterialDescription material(const char* name, ContactResponse response) {
  MaterialDescription m;
  m.name = name;
  m.response = response;
  return m;
}

// A 20 mm block of "bone" inside a 40 mm-radius sphere of "skin", both centred on the body origin
// (at x = 0.1): aiming at the bone from +z must stop at the skin (z = 0.04).
WorldDescription skin_over_bone(ContactMethod method) {
  WorldDescription w;
  w.name = "aim";
  w.materials.push_back(material("bone", ContactResponse::kProxy));
  w.materials.push_back(material("skin", ContactResponse::kPenalty));
  BodyDescription body;
  body.name = "leg";
  body.method = method;
  body.X_world_body = Iso3(Eigen::Translation3d(0.1, 0.0, 0.0));
  SegmentDescription bone;
  bone.name = "bone";
  bone.material = 0;
  bone.mesh = make_box(Vec3(0.01, 0.01, 0.01));
  body.segments.push_back(std::move(bone));
  SegmentDescription skin;
  skin.name = "skin";
  skin.material = 1;
  skin.mesh = make_uv_sphere(0.04, 64, 32);
  body.segments.push_back(std::move(skin));
  w.bodies.push_back(std::move(body));
  ToolDescription tip;
  tip.name = "tip";
  tip.radius_m = 0.005;
  w.tools.push_back(tip);
  return w;
}

TEST(ScenePalpation, AimStopsAtTheFirstSurfaceAlongFrom) {
  for (ContactMethod method :
       {ContactMethod::kExact, ContactMethod::kSphereTree, ContactMethod::kKnee}) {
    SCOPED_TRACE(std::string(to_string(method)));
    const World world(skin_over_bone(method));
    PalpationTargetDescription t;
    t.body = "leg";
    t.segment = "bone";
    t.from_world = Vec3(0, 0, 2.0);  // not unit: normalised
    const PalpationAim aim = aim_palpation_target(world, t);
    EXPECT_EQ(aim.hit_segment, 1u);  // the skin
    // The uv sphere's pole is a vertex: exactly radius 40 mm above the body origin.
    EXPECT_NEAR((aim.surface_world - Vec3(0.1, 0, 0.04)).norm(), 0.0, 2e-6);
  }
}

TEST(ScenePalpation, AimReachesTheSegmentWhenNothingCoversIt) {
  WorldDescription w = skin_over_bone(ContactMethod::kExact);
  w.bodies[0].segments.pop_back();  // no skin
  const World world(std::move(w));
  PalpationTargetDescription t;
  t.body = "leg";
  t.segment = "bone";
  t.from_world = Vec3(-1, 0, 0);
  const PalpationAim aim = aim_palpation_target(world, t);
  EXPECT_EQ(aim.hit_segment, 0u);
  EXPECT_NEAR((aim.surface_world - Vec3(0.09, 0, 0)).norm(), 0.0, 2e-6);
}

TEST(ScenePalpation, PlanPressesDepthPastTheTouchingSphere) {
  const World world(skin_over_bone(ContactMethod::kExact));
  PalpationScriptDescription script;
  PalpationTargetDescription t;
  t.body = "leg";
  t.segment = "bone";
  t.from_world = Vec3::UnitZ();
  t.depth_m = 0.006;
  t.hold_s = 0.25;
  script.targets.push_back(t);
  t.from_world = Vec3::UnitY();
  script.targets.push_back(t);
  const PalpationPlan plan = make_scene_palpation(world, script);
  // Touching: the tool centre one radius (5 mm) out from the skin; pressed 6 mm further in.
  const Vec3 pressed0(0.1, 0.0, 0.04 + 0.005 - 0.006);
  const Vec3 pressed1(0.1, 0.04 + 0.005 - 0.006, 0.0);
  bool saw0 = false;
  bool saw1 = false;
  for (const PalpationPhase& p : plan.phases) {
    if (p.kind == PalpationPhaseKind::kPress) {
      const Vec3& expected = p.target_index == 0 ? pressed0 : pressed1;
      EXPECT_NEAR((p.to_p_world - expected).norm(), 0.0, 3e-6) << p.target_index;
      (p.target_index == 0 ? saw0 : saw1) = true;
    }
  }
  EXPECT_TRUE(saw0 && saw1);
  // The device starts clear of everything: outside the skin by more than the stand-off.
  const Vec3 start = plan.trajectory.samples.front().p_world;
  EXPECT_GT((start - Vec3(0.1, 0, 0)).norm(), 0.04 + script.standoff_m);
}

TEST(ScenePalpation, UnknownNamesAndZeroDirectionAreErrors) {
  const World world(skin_over_bone(ContactMethod::kExact));
  PalpationTargetDescription t;
  t.body = "arm";
  t.segment = "bone";
  EXPECT_THROW((void)aim_palpation_target(world, t), Error);
  t.body = "leg";
  t.segment = "femur";
  try {
    (void)aim_palpation_target(world, t);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("femur"), std::string::npos) << e.what();
  }
  t.segment = "bone";
  t.from_world = Vec3::Zero();
  EXPECT_THROW((void)aim_palpation_target(world, t), Error);
}

}  // namespace
}  // namespace hapsim
