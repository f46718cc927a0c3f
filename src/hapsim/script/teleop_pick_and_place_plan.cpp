#include "hapsim/script/teleop_pick_and_place_plan.h"

namespace hapsim {

PickAndPlacePlan make_teleop_pick_and_place(const PickAndPlaceDescription& description,
                                            const TeleopRigDescription& rig,
                                            const MasterArm& master) {
  PickAndPlaceScript script;
  script.pick_world = rig.ball_start_world;
  script.place_world = description.place_m;
  script.clearance_m = description.clearance_m;
  script.carry_s = description.carry_s;
  script.sample_period_s = description.sample_period_s;
  script.grasp_depth_m =
      grasp_depth_m(rig.gripper.pad_depth_m, rig.gripper.pad_half_m.z(), rig.ball.radius_m);
  script.open_width_m = 0.9 * rig.follower.gripper_max_width_m;
  return make_pick_and_place_plan(script, master, rig.mapping, rig.follower.gripper_max_width_m);
}

}  // namespace hapsim
