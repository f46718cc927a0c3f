// The spring a teleoperation rig describes a contact with (the floor, the sheet, a gripper pad):
// stiffness and damping along the normal, Coulomb friction. rig_world() turns each into a penalty
// material of the world, so the rig's ball meets them through the world's contact code.
#pragma once

namespace hapsim {

struct ContactSpring {
  double stiffness_n_per_m = 2000.0;
  /// Normal damping; with 0.1 kg and 2000 N/m, 8 N·s/m is about critical (ζ ≈ 0.9).
  double damping_n_s_per_m = 8.0;
  /// Coulomb coefficient (static and dynamic).
  double friction = 0.6;
};

}  // namespace hapsim
