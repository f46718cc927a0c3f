// Coulomb friction of a penalty contact (a fingertip on a ball, a ball on the floor): a tangential
// spring, as stiff as the material, from the contact point to where it first stuck, with the
// material's damping on the sliding speed, capped at μs·N; once it slips, the force is μd·N
// against the motion and the stick point is dragged along so the spring holds exactly that. A
// held object stays put instead of creeping, as it would under purely viscous friction.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/force/contact_material.h"

namespace hapsim {

/// Where a contact sticks, in whatever frame the caller keeps it (the surface's body frame, so it
/// moves with a moving body); inactive when the contact is new or has ended.
struct StickPoint {
  bool active = false;
  Vec3 p = Vec3::Zero();
};

/// Friction force on the pressing side (the tool or body whose contact point is
/// `p_contact_world`), perpendicular to the unit normal `n_world`. `v_rel_world`: that point's
/// velocity relative to the surface. `stick_world`: the stick point brought into the world frame
/// by the caller, updated here (set on first touch, dragged when slipping, cleared when the
/// contact carries no normal force). Zero without friction, force or finite input. haptic path
[[nodiscard]] Vec3 contact_friction_force(const ContactMaterial& material, double normal_force_n,
                                          const Vec3& n_world, const Vec3& v_rel_world,
                                          const Vec3& p_contact_world,
                                          StickPoint& stick_world) noexcept;

}  // namespace hapsim
