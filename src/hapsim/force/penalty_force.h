// Penalty contact force (seed 000 §3.2.1, seed 001 Hooke's law): F = k·x along the contact normal,
// with the segment's maximum penetration and maximum force, and normal damping.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/force/contact_material.h"

namespace hapsim {

/// Magnitude of the penalty force (N) for penetration depth `depth_m` (> 0 means pressed in) and
/// approach speed `approach_speed_m_per_s` (> 0 means moving deeper). Never negative (a contact
/// only pushes), never above `material.max_force_n`, never NaN (non-finite input gives 0).
/// haptic path.
double penalty_force_magnitude(const ContactMaterial& material, double depth_m,
                               double approach_speed_m_per_s = 0.0);

/// The penalty force vector on the tool: magnitude above along the outward normal `n_world`.
/// The body receives the opposite force. haptic path.
Vec3 penalty_force(const ContactMaterial& material, double depth_m, const Vec3& n_world,
                   double approach_speed_m_per_s = 0.0);

}  // namespace hapsim
