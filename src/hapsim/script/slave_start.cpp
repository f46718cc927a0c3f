#include "hapsim/script/slave_start.h"

#include "hapsim/kinematics/inverse_kinematics.h"
#include "hapsim/kinematics/slave_follower.h"

#include <cstddef>
#include <vector>

namespace hapsim {

bool solve_slave_start(TeleopRigDescription& rig, const MasterArm& master,
                       const Trajectory& trajectory) {
  const DeviceInput first = trajectory.sample_at(trajectory.start_time_s());
  const Iso3 start = slave_target(
      rig.mapping,
      master.hand_pose({first.joint_rad[0], first.joint_rad[1], first.joint_rad[2]}).translation(),
      first.joint_rad[0]);
  const std::vector<double> seed(static_cast<std::size_t>(rig.slave->dof()), 0.0);
  rig.slave_start_rad.assign(seed.size(), 0.0);
  if (!solve_ik(*rig.slave, start, seed, rig.slave_start_rad).reached) {
    return false;
  }
  // Then onto it to the follower's micrometre: the slave starts at rest, and a start a tenth of a
  // millimetre off is a lag its acceleration limit takes several cycles to close. Without that
  // finer answer the coarse start stands and the first cycles close the gap.
  std::vector<double> fine(seed.size());
  if (solve_ik(*rig.slave, start, rig.slave_start_rad, fine, SlaveFollowerOptions::real_time_ik())
          .reached) {
    rig.slave_start_rad = fine;
  }
  return true;
}

}  // namespace hapsim
