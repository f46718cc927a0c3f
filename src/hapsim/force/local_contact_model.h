// The local contact model (architecture.md#distribution, SPEC §8): what the simulation tells a
// device that may be milliseconds to hundreds of milliseconds away, instead of a raw force. Per
// contact key (device, finger) it is the contact's force as a function of the device's own fresh
// position and velocity,
//
//   F(x, v) = f0 + K·(x − x0) + B·(v − v0)   along the penetration (into the surface),
//   F(x, v) = f0 − K·(x − x0) − B·(v − v0)   in world vectors (K, B restoring: symmetric ≥ 0),
//
// linearised about the state (x0, v0, f0) the simulation computed it at. K must be the stiffness
// the whole contact has *after the tissue gives way*: the contact spring in series with the
// tissue's own compliance. A model with the contact spring alone renders a stiffer spring than
// the simulation settles to, and the mismatch comes back one round trip later as a delayed
// negative stiffness: as unstable as raw force (tests/net/local_model_1dof_test.cpp).
//
// Plain fixed-size data, no network types (net/ carries it; device/ renders it).
#pragma once

#include "hapsim/core/types.h"

#include <array>
#include <cstdint>
#include <limits>

namespace hapsim {

struct LocalContactModel {
  /// The device position and velocity the simulation used, and its force on the device there
  /// (world frame).
  Vec3 x0_world_m = Vec3::Zero();
  Vec3 v0_world_m_per_s = Vec3::Zero();
  Vec3 f0_world_n = Vec3::Zero();
  /// Restoring stiffness and damping about (x0, v0): −dF/dx and −dF/dv, symmetric positive
  /// semi-definite (N/m, N·s/m).
  Mat3 stiffness_n_per_m = Mat3::Zero();
  Mat3 damping_n_s_per_m = Mat3::Zero();
  /// Unit, out of the surface towards the tool: a contact only pushes (F·n ≥ 0). Zero when the
  /// model is free space.
  Vec3 normal_world = Vec3::Zero();
  /// Beyond this distance from x0 the linearisation is not trusted: the device renders zero.
  double validity_radius_m = 0.0;
  /// The most the contact can push along its normal, N (the force caps of its springs, summed):
  /// deeper in, a saturated contact pushes no harder, and the linear model must not say it does.
  /// Infinite: no limit.
  double max_normal_force_n = std::numeric_limits<double>::infinity();
  /// Where the contact is not linear along its normal (a stiffening tissue), its push along the
  /// normal against the depth beyond x0 (metres along −normal): `profile_count` points, depth
  /// increasing and push non-decreasing (a conservative spring), interpolated linearly and
  /// extended past the ends with the end segments' slopes. Along the normal it takes the place
  /// of f0 + K·(x − x0); across it, and for the damping, the linear model stays. Fewer than two
  /// points: no profile. A linear model a round trip old is too soft on a stiffening tissue
  /// for the depth the device has reached since; the profile carries how it stiffens.
  static constexpr int kMaxProfilePoints = 8;
  std::array<double, kMaxProfilePoints> profile_depth_m{};
  std::array<double, kMaxProfilePoints> profile_push_n{};
  int profile_count = 0;
  /// Simulation time of the step that made it (the simulation's clock; the device never compares
  /// it with its own).
  double sim_time_s = 0.0;
  /// Increases by one per model the simulation makes for this key.
  std::uint64_t sequence = 0;
  /// The sequence of the device state this model answered (the device measures a model's age in
  /// its own cycles from it).
  std::uint64_t device_sequence = 0;
  /// False: no contact model (the device renders zero).
  bool valid = false;
};

/// 1 / (1/k_contact + 1/k_tissue): the contact spring in series with the tissue. An infinite
/// tissue stiffness (a rigid body) gives the contact stiffness; a non-positive or NaN input
/// gives 0 (no stiffness is safer than a wrong one).
[[nodiscard]] double series_stiffness_n_per_m(double contact_stiffness_n_per_m,
                                              double tissue_stiffness_n_per_m) noexcept;

/// The model's force at the device's (x, v): f0 − K·(x − x0) − B·(v − v0), its push along the
/// normal from the profile where there is one; zero for an invalid model or non-finite input. No
/// validity radius, clamping or push-only rule: the device's renderer
/// (device/local_model_renderer.h) applies those. haptic path
[[nodiscard]] Vec3 local_model_force(const LocalContactModel& model, const Vec3& x_world_m,
                                     const Vec3& v_world_m_per_s) noexcept;

/// The profile's push at `depth_m` beyond x0 (linear between points, the end slopes beyond);
/// NaN without a profile. haptic path
[[nodiscard]] double profile_push_n(const LocalContactModel& model, double depth_m) noexcept;

/// The force a model should carry when the simulation's tissue is driven by the force the device
/// actually rendered (SPEC §8), along the contact normal: the rendered force F_r, corrected by
/// the model stiffness K for how far the contact spring's compression c = x0 − y (device minus
/// tissue surface) is from the compression F_r/k_c that force implies:
///   f0 = F_r + K·(c − F_r/k_c).
/// With K the series stiffness this is the quasi-static force at x0 to first order, whatever the
/// delay; with K = k_c it is the contact spring's k_c·c, whose error returns through the tissue
/// with gain k_c/k_tissue each round trip.
[[nodiscard]] double tissue_coupled_force_n(double rendered_force_n, double compression_m,
                                            double contact_stiffness_n_per_m,
                                            double model_stiffness_n_per_m) noexcept;

}  // namespace hapsim
