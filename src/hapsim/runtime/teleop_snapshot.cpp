#include "hapsim/runtime/teleop_snapshot.h"

#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/rig/rig_controller.h"

#include <algorithm>

namespace hapsim {

TeleopSnapshot make_teleop_snapshot(const World& world) {
  TeleopSnapshot s;
  const RigState& rig = *rig_state(world);
  s.slave_q.assign(rig.slave->q().size(), 0.0);
  s.time_s = rig.result.time_s;
  fill_teleop_snapshot(s, world);
  return s;
}

// haptic path
void fill_teleop_snapshot(TeleopSnapshot& s, const World& world) noexcept {
  const RigState& rig = *rig_state(world);
  const TeleopStepResult& r = rig.result;
  const bool stepped = r.time_s > 0.0;
  const auto q = rig.slave->q();
  std::copy_n(q.begin(), std::min(q.size(), s.slave_q.size()), s.slave_q.begin());
  s.X_world_tool = rig.slave->tip_pose();
  // Before the first step the gripper report is empty: the pads are where the slave holds them.
  s.gripper_width_m = stepped ? r.gripper.width_m : rig.slave->gripper_width_m();
  s.pad_force_n = r.gripper.pad_force_n;
  s.grasp_force_n = r.gripper.grasp_force_n();
  s.held = r.held;
  const std::size_t sheet = rig.description->sheet_body;
  s.sheet_depth_m =
      sheet != TeleopRigDescription::kNoBody ? world.sheet(sheet)->max_depth_m() : 0.0;
  s.master_joint_rad = r.master_arm_rad;
  s.master_finger_rad = r.master_finger_rad;
  s.X_master_hand = rig_controller(world.description())->master().hand_pose(r.master_arm_rad);
}

}  // namespace hapsim
