// The ball's surroundings in a teleoperation rig: the virtual sheet (placed in the world) and a
// floor plane, with the contact springs the ball meets them with. rig_world() makes both world
// bodies; BallContactReport is what the rig reports of them each step.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/rig/contact_spring.h"

namespace hapsim {

struct BallEnvironmentOptions {
  Iso3 X_world_sheet = Iso3::Identity();
  /// Softer than the sheet under a contact (the sheet's field lags the push by one step; the
  /// world checks it at build).
  ContactSpring sheet_contact;
  /// Floor: the plane z = floor_z_m (world), facing up. Off: nothing below the sheet.
  bool has_floor = true;
  double floor_z_m = -0.1;
  ContactSpring floor_contact{.stiffness_n_per_m = 20000.0, .damping_n_s_per_m = 25.0};
};

struct BallContactReport {
  bool on_sheet = false;
  bool on_floor = false;
  /// Force the sheet and the floor put on the ball this step, world frame.
  Vec3 sheet_force_world_n = Vec3::Zero();
  Vec3 floor_force_world_n = Vec3::Zero();
  /// What the sheet took this step: the contact point (sheet frame) and the push into it.
  Vec3 sheet_contact_sheet = Vec3::Zero();
  double sheet_push_n = 0.0;
};

}  // namespace hapsim
