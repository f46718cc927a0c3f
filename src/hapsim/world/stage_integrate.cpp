// Stage 4: rigid bodies. The rig's ball moves under gravity and the gripper pads' force, and rests
// on the virtual sheet (contact springs; the sheet's Gaussian field takes the ball's imprint) or
// on the floor; a held ball moves with the gripper (the respond stage put it there).
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

namespace hapsim::stage {

// haptic path
void integrate(const WorldModel& /*model*/, WorldState& state, double dt_s) noexcept {
  if (!state.rig) {
    return;
  }
  RigState& rig = *state.rig;
  TeleopStepResult& r = rig.result;
  r.ball_contacts = rig.environment->step(rig.ball, r.gripper.force_on_ball_world_n, dt_s);
  r.ball_p_world = rig.ball.p_world();
  r.held = r.gripper.held;
  r.sheet_depth_m = rig.sheet->max_depth_m();
}

}  // namespace hapsim::stage
