// The ball's surroundings in the teleoperation scene: the virtual sheet (placed in the world) and
// a floor plane. Each cycle the ball feels penalty contacts with both (the sheet's *elastic*
// field, since the ball's own imprint would otherwise hide the sheet from it), plus whatever
// force the caller adds (gripper pads); then the sheet takes the ball's push as this cycle's
// contact and transcribes the ball's lower cap into its surface (seed 000 §3.2.2).
//
// The sheet's elastic field lags the ball by one cycle; that loop settles as long as the contact
// spring is softer than the sheet under the ball (2000 N/m against ~4300 N/m for the paper's
// sheet), which the constructor checks.
#pragma once

#include "hapsim/deform/virtual_sheet.h"
#include "hapsim/dynamics/contact_spring.h"
#include "hapsim/dynamics/rigid_ball.h"

namespace hapsim {

struct BallEnvironmentOptions {
  Iso3 X_world_sheet = Iso3::Identity();
  ContactSpring sheet_contact;
  /// Floor: the plane z = floor_z_m (world), facing up. Off: nothing below the sheet.
  bool has_floor = true;
  double floor_z_m = -0.1;
  ContactSpring floor_contact{.stiffness_n_per_m = 20000.0, .damping_n_s_per_m = 25.0};
};

struct BallContactReport {
  bool on_sheet = false;
  bool on_floor = false;
  /// Force the sheet and the floor put on the ball this cycle, world frame.
  Vec3 sheet_force_world_n = Vec3::Zero();
  Vec3 floor_force_world_n = Vec3::Zero();
  /// What the sheet took this cycle: the contact point (sheet frame) and the push into it.
  Vec3 sheet_contact_sheet = Vec3::Zero();
  double sheet_push_n = 0.0;
};

class BallEnvironment {
 public:
  /// Holds `sheet` (not owned; must outlive this). Throws hapsim::Error when the sheet contact
  /// spring is not softer than the sheet itself under a contact (the loop would not settle).
  BallEnvironment(VirtualSheet& sheet, BallEnvironmentOptions options = {});

  /// One cycle: contacts, then the ball moves (unless held), then the sheet deforms and takes
  /// the imprint. `extra_force_world_n`: other forces on the ball (gripper pads). haptic path
  BallContactReport step(RigidBall& ball, const Vec3& extra_force_world_n, double dt_s) noexcept;

  [[nodiscard]] const VirtualSheet& sheet() const { return *sheet_; }
  [[nodiscard]] const BallEnvironmentOptions& options() const { return options_; }

 private:
  VirtualSheet* sheet_;
  BallEnvironmentOptions options_;
  Iso3 X_sheet_world_;
  FrictionAnchor sheet_anchor_;
  FrictionAnchor floor_anchor_;
};

}  // namespace hapsim
