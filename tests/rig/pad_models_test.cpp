// The gripper pads' served models (rig/pad_models.h) on scenes/teleop.json as `hapsim run`
// assembles it, against what the world itself did: each pad's force and push are its contact's
// with the ball (the rig's own report), their sum is the force at the slave's tool the rig's
// command feels, the stiffness predicts how the grip grows as the pads close on the ball (the next
// steps of the world, not the model's own formula), and the carry moves the pads in the world but
// not in the grip's frame the models are given in.
#include "hapsim/rig/pad_models.h"
#include "hapsim/force/local_contact_model.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/world/world.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace hapsim {
namespace {

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/teleop.json";

struct PadStep {
  double time_s = 0.0;
  std::array<LocalContactModel, 2> models;
  std::array<double, 2> pad_force_n{};  // the rig's report: each pad's push on the ball
  std::array<Vec3, 2> pad_world{};
  Vec3 tool_force_world_n = Vec3::Zero();
  bool held = false;
};

std::vector<PadStep> run_pick(double duration_s) {
  std::vector<PadStep> steps;
  RunSetup setup = make_run_setup(load_scene(kScene), DeviceChoice::scene_script());
  const World& world = *setup.world;
  const TeleopRigDescription* d = rig_description(world.description());
  if (d == nullptr) {
    return steps;
  }
  SessionOptions options;
  options.duration_s = duration_s;
  options.dt_s = setup.scene.run.dt_s;
  options.after_cycle = [&](std::size_t) {
    const TeleopStepResult& r = *rig_result(world.last_result());
    PadStep s;
    s.time_s = r.time_s;
    build_pad_models(*d, world.state(), steps.size() + 1, 0.01, s.models);
    s.pad_force_n = r.gripper.pad_force_n;
    for (std::size_t i = 0; i < 2; ++i) {
      s.pad_world[i] = world.body_pose(d->pad_body[i]).translation();
    }
    s.tool_force_world_n = r.tool_force_world_n;
    s.held = r.held;
    steps.push_back(s);
  };
  (void)run_session(*setup.world, *setup.device, options);
  return steps;
}

TEST(PadModels, AreThePadsContactsWithTheBallInTheGripsFrame) {
  const std::vector<PadStep> steps = run_pick(6.0);  // grasped at 3.946 s, carried after
  ASSERT_GT(steps.size(), 5000u) << "the teleop scene has no rig";
  std::size_t free = 0;
  std::size_t held = 0;
  std::size_t carried = 0;
  for (std::size_t k = 1; k < steps.size(); ++k) {
    const PadStep& s = steps[k];
    if (s.pad_force_n[0] == 0.0 && s.pad_force_n[1] == 0.0) {
      EXPECT_FALSE(s.models[0].valid || s.models[1].valid) << s.time_s;  // free space
      ++free;
      continue;
    }
    if (!s.held || !s.models[0].valid || !s.models[1].valid) {
      continue;
    }
    ++held;
    for (std::size_t i = 0; i < 2; ++i) {
      const LocalContactModel& m = s.models[i];
      // Its push is the pad's on the ball, out of the ball; capped at the gripper's limit.
      EXPECT_NEAR(m.f0_world_n.dot(m.normal_world), s.pad_force_n[i], 1e-9) << s.time_s;
      EXPECT_NEAR(m.normal_world.norm(), 1.0, 1e-12);
      EXPECT_DOUBLE_EQ(m.max_normal_force_n, 20.0);
      EXPECT_NEAR((m.stiffness_n_per_m * m.normal_world).norm(), 5000.0, 1e-9);
      EXPECT_EQ(m.sequence, k + 1);
    }
    // Together the force at the slave's tool the rig's command felt (no palm or stem contact).
    EXPECT_LT((s.models[0].f0_world_n + s.models[1].f0_world_n - s.tool_force_world_n).norm(), 1e-9)
        << s.time_s;
    // In the grip's frame: each pad half the way from the other, whatever carries the grip.
    const Vec3 half_apart = 0.5 * (s.pad_world[0] - s.pad_world[1]);
    EXPECT_LT((s.models[0].x0_world_m - half_apart).norm(), 1e-12);
    EXPECT_LT((s.models[1].x0_world_m + half_apart).norm(), 1e-12);
    // The carry moves the pads in the world by up to ~0.2 mm a step, not in the grip's frame.
    const PadStep& before = steps[k - 1];
    const double moved_m = (s.pad_world[0] - before.pad_world[0]).norm();
    if (before.models[0].valid && moved_m > 5e-5 &&
        (s.models[0].x0_world_m - before.models[0].x0_world_m).norm() < 0.01 * moved_m) {
      ++carried;
    }
  }
  EXPECT_GT(free, 3000u);
  EXPECT_GT(held, 1500u);
  EXPECT_GT(carried, 400u) << "the pads should carry the ball over many steps";

  // As the pads close on the ball (before the gripper's limit), each step's model predicts the
  // next step's push from how far the pads came together: K·(x0 − x)·n against the world's.
  std::size_t predicted = 0;
  for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
    const PadStep& s = steps[k];
    const PadStep& next = steps[k + 1];
    if (!s.models[0].valid || !next.models[0].valid || s.pad_force_n[0] < 0.5 ||
        next.pad_force_n[0] > 19.0 || next.pad_force_n[0] <= s.pad_force_n[0]) {
      continue;
    }
    const LocalContactModel& m = s.models[0];
    const Vec3 f_model = local_model_force(m, next.models[0].x0_world_m, m.v0_world_m_per_s);
    const double world_grew_n = next.pad_force_n[0] - s.pad_force_n[0];
    const double model_grew_n = f_model.dot(m.normal_world) - s.pad_force_n[0];
    EXPECT_NEAR(model_grew_n, world_grew_n, 0.05 * world_grew_n + 1e-3) << s.time_s;
    ++predicted;
  }
  EXPECT_GE(predicted, 5u) << "the pads should close on the ball over several steps";
}

}  // namespace
}  // namespace hapsim
