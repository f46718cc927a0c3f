// The device side of a local contact model (SPEC §8, force/local_contact_model.h): renders the
// newest model at 1 kHz from the device's own fresh position and velocity, with the safety rules
// a model from far away needs. One renderer per contact key (device, finger).
//
//  * A new model is blended in over `blend_time_s`: at its arrival the difference between what
//    was rendered and what the new model gives at the same place is kept as an offset that
//    decays linearly to zero, so a jump between models is felt as a ramp, while a new model
//    that agrees with the old one (the steady stream of a contact) is rendered as it is, with
//    no lag: the field is always the newest model's.
//  * Zero outside the model's validity radius around x0; push-only along its normal, and no more
//    push along it than the model's force cap (a saturating contact).
//  * Clamped to `max_force_n` (the device profile's rating).
//  * Stale-model fade: once the newest model is older than `stale_after_s` by the *local receive
//    clock* (never the simulation's: clocks are not compared across hosts), the force fades
//    linearly to zero over `fade_time_s`.
//  * Re-engagement: a model that ends a stale spell (an outage, a restarted simulation) ramps in
//    over `reengage_time_s` instead. The hand kept pushing while the force was off, so the
//    device is likely deeper than where the contact last held; the contact comes back as a
//    push that grows, not as a jolt of the force at that depth (twice the hold and more).
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
  double reengage_time_s = 0.5;
};

/// What render() did to the force, counted since construction (for the device's health report).
struct LocalModelRenderCounts {
  std::uint64_t outside_radius = 0;
  std::uint64_t pull_zeroed = 0;  ///< the model would have pulled: zero instead
  std::uint64_t clamped = 0;
  std::uint64_t capped = 0;     ///< the push along the normal bounded by the model's force cap
  std::uint64_t fading = 0;     ///< cycles rendered with a stale model (fading or faded out)
  std::uint64_t reengaged = 0;  ///< models that ended a stale spell (ramped in slowly)
  std::uint64_t nonfinite = 0;
  std::uint64_t models_received = 0;
  std::uint64_t models_refused = 0;  ///< non-finite or negative-stiffness models
};

class LocalModelRenderer {
 public:
  /// Throws hapsim::Error unless max_force_n is finite and > 0 and the times are finite and ≥ 0.
  explicit LocalModelRenderer(LocalModelRenderOptions options = {});

  /// A model arrived at local time `now_s`. A model with non-finite fields, or a K or B with a
  /// negative diagonal, is refused (counted) and the previous one kept. The blend starts from
  /// the force last rendered (zero before any). haptic path
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
  /// The force at (x, v) by every rule of the header but the non-finite input check; what each
  /// rule did is counted into `counts` (none: a look at what would be felt, counted nowhere).
  [[nodiscard]] Vec3 shaped(const Vec3& x_world_m, const Vec3& v_world_m_per_s, double now_s,
                            LocalModelRenderCounts* counts) const noexcept;
  /// What is left of the blend's and the re-engagement's offsets at `now_s`.
  [[nodiscard]] Vec3 offset(double now_s) const noexcept;
  [[nodiscard]] Vec3 reengage_offset(double now_s) const noexcept;

  LocalModelRenderOptions options_;
  LocalContactModel newest_;
  /// Rendered minus the newest model's force where the device last was, when it arrived.
  Vec3 offset_n_ = Vec3::Zero();
  /// Where the device was at the last render() and what it got.
  Vec3 last_x_m_ = Vec3::Zero();
  Vec3 last_v_m_per_s_ = Vec3::Zero();
  Vec3 last_force_n_ = Vec3::Zero();
  bool has_rendered_ = false;
  double received_s_ = 0.0;
  /// A re-engagement's offset (rendered minus the model's when it ended a stale spell), dying
  /// out over reengage_time_s from reengage_from_s_, beside the blend's.
  Vec3 reengage_offset_n_ = Vec3::Zero();
  double reengage_from_s_ = 0.0;
  bool has_model_ = false;
  LocalModelRenderCounts counts_;
};

}  // namespace hapsim
