// The rig's report (rig_controller.h), observed after the step from its result alone, as the
// assessment scorer reads cycle records: whether the grasp holds, where the ball is and what
// carries it (the sheet, the floor), how deep the sheet is dented. Nothing here changes the step.
#include "hapsim/rig/rig_controller.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <algorithm>
#include <array>

namespace hapsim {

namespace {

// The grasp holds when both pads press the ball from opposite sides with friction able to carry
// its weight, μ·(N₁ + N₂) ≥ safety · m·g; it ends when either has let go for kReleaseAfterS (a
// served slave jerked by a stalled cycle lifts a pad off for a step, and the ball is carried on).
// The ball stays a free body held by friction: this is a report. haptic path
void observe_grasp(const TeleopRigDescription& d, const WorldModel& model, const StepResult& step,
                   bool& held, double& lost_since_s, GripperReport& g) noexcept {
  g.grasped_now = false;
  g.released_now = false;
  g.released_at_s = -1.0;
  std::array<Vec3, 2> normals{Vec3::Zero(), Vec3::Zero()};
  for (const BodyContact& c : step.body_contacts) {
    for (std::size_t i = 0; i < 2; ++i) {
      if (c.body == BodyIndex{d.ball_body} && c.other_body == BodyIndex{d.pad_body[i]}) {
        normals[i] = c.normal_world;
      }
    }
  }
  const double weight = d.ball.mass_kg * model.description().gravity_m_per_s2.norm();
  const bool both =
      g.pad_force_n[0] > 0.0 && g.pad_force_n[1] > 0.0 && normals[0].dot(normals[1]) < -0.5;
  const double friction = d.gripper.pad_contact.friction;
  if (!held && both &&
      friction * (g.pad_force_n[0] + g.pad_force_n[1]) >= d.gripper.safety_factor * weight) {
    held = true;
    g.grasped_now = true;
    lost_since_s = -1.0;
  } else if (held && both) {
    lost_since_s = -1.0;
  } else if (held) {
    if (lost_since_s < 0.0) {
      lost_since_s = step.time_s;
    }
    // Half a microsecond short: the step times are sums of dt_s.
    if (step.time_s - lost_since_s >= GripperReport::kReleaseAfterS - 5e-7) {
      held = false;
      g.released_now = true;
      g.released_at_s = lost_since_s;
      lost_since_s = -1.0;
    }
  }
  g.held = held;
}

// Where the ball is and what carries it (the sheet, the floor). haptic path
void observe_ball(const TeleopRigDescription& d, const StepResult& step,
                  TeleopStepResult& r) noexcept {
  BallContactReport& b = r.ball_contacts;
  b = BallContactReport{};
  for (const BodyContact& c : step.body_contacts) {
    if (c.body != BodyIndex{d.ball_body}) {
      continue;
    }
    if (c.other_body == BodyIndex{d.sheet_body}) {
      b.on_sheet = c.force_world_n.squaredNorm() > 0.0;
      b.sheet_force_world_n += c.force_world_n;
      const Iso3& X_sheet_world = step.bodies[d.sheet_body].X_body_world;
      b.sheet_contact_sheet = X_sheet_world * c.point_world;
      b.sheet_push_n = std::max(0.0, (X_sheet_world.linear() * c.force_world_n).z());
    } else if (c.other_body == BodyIndex{d.floor_body}) {
      b.on_floor = c.force_world_n.squaredNorm() > 0.0;
      b.floor_force_world_n += c.force_world_n;
    }
  }
  r.ball_p_world = step.bodies[d.ball_body].X_world_body.translation();
}

}  // namespace

// haptic path
void RigState::observe(const WorldModel& model, const StepResult& step) noexcept {
  const TeleopRigDescription& d = *description;
  result.time_s = step.time_s;
  if (d.ball_body != TeleopRigDescription::kNoBody) {
    observe_grasp(d, model, step, held, grip_lost_since_s, result.gripper);
    observe_ball(d, step, result);
  }
  result.held = result.gripper.held;
  result.sheet_depth_m =
      d.sheet_body != TeleopRigDescription::kNoBody && sheet_index < step.sheet_depth_m.size()
          ? step.sheet_depth_m[sheet_index]
          : 0.0;
}

}  // namespace hapsim
