// The device side of a local contact model (SPEC §8, force/local_contact_model.h): renders the
// newest model at 1 kHz from the device's own fresh position and velocity, with the safety rules
// a model from far away needs. One renderer per contact key (device, finger).
//
//  * A new model is blended in over `blend_time_s` (a linear blend of the two models' affine
//    forms, so a jump in f0 between models is never felt as a step).
//  * Zero outside the model's validity radius around x0; push-only along its normal.
//  * Clamped to `max_force_n` (the device profile's rating).
//  * Stale-model fade: once the newest model is older than `stale_after_s` by the *local receive
//    clock* (never the simulation's: clocks are not compared across hosts), the force fades
//    linearly to zero over `fade_time_s`.
// Allocation-free and non-blocking; the owner feeds it models it took without blocking.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/force/local_contact_model.h"

#include <cstdint>

namespace hapsim {

struct LocalModelRenderOptions {
  double max_force_n = 10.0;
  double blend_time_s = 0.02;
  double stale_after_s = 0.1;
  double fade_time_s = 0.05;
};

/// What render() did to the force, counted since construction (for the device's health report).
struct LocalModelRenderCounts {
  std::uint64_t outside_radius = 0;
  std::uint64_t pull_zeroed = 0;  ///< the model would have pulled: zero instead
  std::uint64_t clamped = 0;
  std::uint64_t fading = 0;  ///< cycles rendered with a stale model (fading or faded out)
  std::uint64_t nonfinite = 0;
  std::uint64_t models_received = 0;
  std::uint64_t models_refused = 0;  ///< non-finite or negative-stiffness models
};

class LocalModelRenderer {
 public:
  /// Throws hapsim::Error unless max_force_n is finite and > 0 and the times are finite and ≥ 0.
  explicit LocalModelRenderer(LocalModelRenderOptions options = {});

  /// A model arrived at local time `now_s`. A model with non-finite fields, or a K or B with a
  /// negative diagonal, is refused (counted) and the previous one kept. haptic path
  void receive(const LocalContactModel& model, double now_s) noexcept;

  /// The force for the device at local time `now_s`, at its position and velocity. haptic path
  [[nodiscard]] Vec3 render(const Vec3& x_world_m, const Vec3& v_world_m_per_s,
                            double now_s) noexcept;

  /// 1 while the newest model is fresh, falling to 0 as it goes stale; 0 before any model.
  [[nodiscard]] double freshness(double now_s) const noexcept;
  [[nodiscard]] const LocalModelRenderCounts& counts() const noexcept { return counts_; }
  [[nodiscard]] const LocalContactModel& newest() const noexcept { return newest_; }
  [[nodiscard]] const LocalModelRenderOptions& options() const noexcept { return options_; }

 private:
  /// F = c − K·x − B·v: a model's affine form, which blends linearly.
  struct Affine {
    Vec3 c_n = Vec3::Zero();
    Mat3 k_n_per_m = Mat3::Zero();
    Mat3 b_n_s_per_m = Mat3::Zero();
  };
  [[nodiscard]] static Affine affine_of(const LocalContactModel& model) noexcept;
  [[nodiscard]] Affine blended(double now_s) const noexcept;

  LocalModelRenderOptions options_;
  LocalContactModel newest_;
  Affine from_;  ///< what was rendered when the newest model arrived
  Affine to_;    ///< the newest model
  double received_s_ = 0.0;
  bool has_model_ = false;
  LocalModelRenderCounts counts_;
};

}  // namespace hapsim
