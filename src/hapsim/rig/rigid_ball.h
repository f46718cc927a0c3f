// The rigid ball a teleoperated slave picks and places (paper 000 §4): rig_world() makes it a
// dynamic sphere body of the world (integrated by the world's integrate stage).
#pragma once

#include "hapsim/core/types.h"

namespace hapsim {

struct RigidBallParams {
  double mass_kg = 0.1;
  double radius_m = 0.03;
  Vec3 gravity_m_per_s2 = Vec3(0.0, 0.0, -9.81);
};

}  // namespace hapsim
