// The force between a rigid body and whatever it touches (the floor, the sheet, a gripper pad):
// a penalty spring along the contact normal with damping that only pushes (never pulls the body
// back in), and Coulomb friction. Friction is a tangential spring to a stick point (the anchor)
// capped at μ·N — the anchor slides when the cap is reached — so a body at rest on a slight slope
// stays put instead of creeping, as it would under purely viscous friction.
#pragma once

#include "hapsim/core/types.h"

namespace hapsim {

struct ContactSpring {
  double stiffness_n_per_m = 2000.0;
  /// Normal damping; with 0.1 kg and 2000 N/m, 8 N·s/m is about critical (ζ ≈ 0.9).
  double damping_n_s_per_m = 8.0;
  /// Coulomb coefficient; the stick spring and its damping.
  double friction = 0.6;
  double friction_stiffness_n_per_m = 2000.0;
  double friction_damping_n_s_per_m = 8.0;
};

/// Where a contact sticks; inactive when the contact is new (or after it ended).
struct FrictionAnchor {
  bool active = false;
  Vec3 p_world = Vec3::Zero();
};

/// Force on the body. `penetration_m` > 0 when touching, `normal` the unit direction pushing the
/// body out, `v_rel` the body's velocity relative to the surface, `p_body` the point that sticks
/// (e.g. the body's centre). The anchor is updated (set on first touch, dragged when slipping,
/// cleared when not touching). Zero force when not touching or on non-finite input. haptic path
[[nodiscard]] Vec3 contact_spring_force(const ContactSpring& spring, double penetration_m,
                                        const Vec3& normal, const Vec3& v_rel, const Vec3& p_body,
                                        FrictionAnchor& anchor) noexcept;

}  // namespace hapsim
