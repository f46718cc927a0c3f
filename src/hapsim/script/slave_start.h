// Where a teleoperation rig's slave starts: the joints that put its flange where the master's first
// scripted or recorded pose asks (one cold IK before the run), so the slave does not leap at the
// first step. scene/teleop_setup.h solves it once for the trajectory it chose.
#pragma once

#include "hapsim/kinematics/master_arm.h"
#include "hapsim/rig/rig_description.h"
#include "hapsim/script/trajectory.h"
#include "hapsim/world/world_description.h"

namespace hapsim {

/// Sets `rig.slave_start_rad` (dof() values) to the slave's joints for the master's pose at the
/// trajectory's first sample, solved by IK from all-zero joints through the rig's mapping.
/// Returns false when that pose puts the slave's target out of its reach.
[[nodiscard]] bool solve_slave_start(TeleopRigDescription& rig, const MasterArm& master,
                                     const Trajectory& trajectory);

}  // namespace hapsim
