// How a segment (a bone, a muscle, the sheet) answers a press: Hooke stiffness with the knee
// paper's per-segment maximum penetration and maximum force, plus damping and Coulomb friction.
#pragma once

namespace hapsim {

struct ContactMaterial {
  /// Hooke's law F = k·x along the contact normal (N/m).
  double stiffness_n_per_m = 500.0;
  /// Penetration beyond which the spring stops growing (m). Soft tissue: large; bone: small.
  double max_penetration_m = 0.01;
  /// Force cap of the segment (N). Soft tissue: small; bone: large.
  double max_force_n = 5.0;
  /// Viscous damping along the normal, opposing the approach speed (N·s/m).
  double damping_n_s_per_m = 0.0;
  /// Coulomb friction on the proxy: static (stick) and dynamic (slip) coefficients.
  double static_friction = 0.0;
  double dynamic_friction = 0.0;
};

/// A body that does not give (a material's `"rigid": true`, the teleoperation rig's ball): its
/// stiffness and damping so far above any other body's that in series with another material the
/// pair is that material's spring (1/(1/k + 1e-12) = k to 1e-9 relative at k = 5000 N/m). A tool
/// pressing it feels the device's stiffest (effective_material clamps the stiffness to the
/// device's rating and takes the passivity floor for the damping).
inline constexpr double kRigidStiffness_n_per_m = 1e12;
inline constexpr double kRigidDamping_n_s_per_m = 1e12;

[[nodiscard]] constexpr bool is_rigid(const ContactMaterial& m) noexcept {
  return m.stiffness_n_per_m >= kRigidStiffness_n_per_m;
}

}  // namespace hapsim

namespace hapsim {

/// The contact between two bodies of materials `a` and `b` (paper 000 §3.2.1: one spring between
/// the points of closest approach, equal and opposite on both): both give way in series —
/// stiffness and damping in series (so each one's passivity floor holds for the pair), the
/// penetrations add up, the force is capped by the weaker; friction the larger of the two (as
/// MuJoCo does), so a frictionless body takes the other's.
[[nodiscard]] ContactMaterial combine_materials(const ContactMaterial& a,
                                                const ContactMaterial& b) noexcept;

}  // namespace hapsim
