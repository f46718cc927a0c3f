// A 6-axis Motoman-like arm as a Denavit–Hartenberg chain: the slave's default when the real GP7
// URDF (../shared/data/motoman_gp7) is not at hand. Link lengths, joint limits and joint speed
// limits follow the GP7's URDF (0.33 m base, 0.445 m upper arm, 0.44 m forearm, 0.08 m flange),
// so scripts written for one suit the other; the zero pose differs (DH convention).
#pragma once

#include "hapsim/kinematics/serial_chain.h"

namespace hapsim {

[[nodiscard]] SerialChain make_procedural_motoman();

}  // namespace hapsim
