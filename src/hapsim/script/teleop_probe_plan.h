// Tele-palpation's scripted master: a probe path (where the tool the slave carries should be: a
// scene palpation planned on the tissue, script/scene_palpation_plan.h) turned into the master's
// input. Each sample's probe centre → the slave's flange (the probe's offset in the flange frame
// taken off, the flange pointing down as the teleop mapping holds it) → the master's joints
// (master_flange_ik.h); the gripper closed.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/rig/rig_description.h"
#include "hapsim/script/trajectory.h"

namespace hapsim {

/// The master's input (joint_rad[0..2] arm, finger_rad[0..1] fingers) that makes the slave carry
/// a probe whose centre sits at `probe_offset_tool` in the flange frame along `probe` (its samples'
/// p_world: the probe's centre). Throws hapsim::Error ("tele-palpation script") when a sample is
/// out of the master's reach through the mapping, or `probe` is empty.
[[nodiscard]] Trajectory make_teleop_probe_plan(const Trajectory& probe,
                                                const TeleopRigDescription& rig,
                                                const MasterArm& master,
                                                const Vec3& probe_offset_tool);

}  // namespace hapsim
