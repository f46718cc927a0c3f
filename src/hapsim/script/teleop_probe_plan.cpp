#include "hapsim/script/teleop_probe_plan.h"

#include "hapsim/core/error.h"
#include "hapsim/script/master_flange_ik.h"

#include <utility>
#include <vector>

namespace hapsim {

Trajectory make_teleop_probe_plan(const Trajectory& probe, const TeleopRigDescription& rig,
                                  const MasterArm& master, const Vec3& probe_offset_tool) {
  const char* where = "tele-palpation script";
  if (probe.empty()) {
    throw Error(where, "the probe's path has no samples");
  }
  MasterFlangeIk ik(master, rig.mapping, rig.follower.gripper_max_width_m, where);
  // The slave's flange turns with the master's base about the vertical only (slave_target): an
  // offset along the flange's own axis lands at the same place whatever that turn.
  const Vec3 offset_world = rig.mapping.R_tool * probe_offset_tool;
  std::vector<DeviceInput> samples;
  samples.reserve(probe.size());
  for (const DeviceInput& s : probe.samples) {
    samples.push_back(ik.input_for(s.time_s, s.p_world - offset_world, 0.0));
  }
  return make_trajectory(std::move(samples), 2, 3, where);
}

}  // namespace hapsim
