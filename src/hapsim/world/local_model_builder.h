// The simulation side of the local contact model (force/local_contact_model.h, SPEC §8): after a
// World step, per tool (one contact key: the probe, or one fingertip of the glove hand), the
// model the device renders until the next one arrives:
//   x0, v0  the tool's position and velocity this step (the device pose the step used),
//   f0      the tool's force this step,
//   K       Σ over the tool's contacts of k_series · n nᵀ, with k_series the contact's material
//           stiffness (already clamped to the device) in series with the segment's tissue
//           stiffness; 0 along a contact whose spring is saturated (at its maximum penetration
//           or force: pressing further adds nothing),
//   B       Σ material damping · n nᵀ,
//   cap     Σ per contact of the force its spring saturates at (force cap or penetration limit;
//           the god-object's spring once), and never below |f0|: deeper in, a saturated contact
//           pushes no harder, and a device a round trip ahead must not feel it push harder.
// Tissue stiffness per segment:
//   * a Gaussian sheet gives way under a push with its own compliance (the profile's depth per
//     newton under the contact, the same number WorldModel checks the contact spring against):
//     the contact spring sits on it in series;
//   * a vertex-deflection segment's surface follows the tool (eq. 1: δ(0) = x) while its force is
//     k·(rest depth): the material's k already is the whole press's stiffness, the dent only
//     shapes the surface and what *other* tools feel — tissue stiffness ∞;
//   * rigid segments: ∞ (K is the contact stiffness).
// Allocation-free per step; the per-segment tissue stiffness is computed once.
#pragma once

#include "hapsim/force/local_contact_model.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <cstdint>
#include <span>
#include <vector>

namespace hapsim {

struct LocalModelBuildOptions {
  /// How far from x0 the device may trust the model (beyond: zero force). A 40 ms round trip at
  /// 0.2 m/s is 8 mm.
  double validity_radius_m = 0.01;
};

class LocalModelBuilder {
 public:
  explicit LocalModelBuilder(const WorldModel& model, LocalModelBuildOptions options = {});

  /// Fills out[t] for every tool t < out.size() from the step `state` just took. `sequence` is
  /// the models' sequence (one per step), `device_sequence` the device state the step used.
  /// A tool without contacts gets a valid free-space model (zero force, no stiffness). haptic path
  void build(const WorldState& state, std::uint64_t sequence, std::uint64_t device_sequence,
             std::span<LocalContactModel> out) const noexcept;

  /// The tissue stiffness of flat segment `flat`, N/m (∞ where the contact spring is the whole
  /// stiffness).
  [[nodiscard]] double tissue_stiffness_n_per_m(std::size_t flat) const {
    return tissue_stiffness_n_per_m_.at(flat);
  }

 private:
  const WorldModel* model_;
  LocalModelBuildOptions options_;
  std::vector<double> tissue_stiffness_n_per_m_;  ///< per flat segment
};

}  // namespace hapsim
