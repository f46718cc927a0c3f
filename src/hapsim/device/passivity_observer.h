// The device side's last guard (SPEC §8, architecture.md#distribution): a one-port time-domain
// passivity observer and controller (Hannaford & Ryu, "Time-domain passivity control of haptic
// interfaces", IEEE T-RA 18(1), 2002), impedance causality: velocity in, force out.
//
// Sign convention. `f_n` is the force the rendered environment puts on the device (what the
// device pushes the user's hand with), `v_m_per_s` the device's velocity. The power flowing
// *into* the environment is −f·v, so the observed energy
//
//   E(n) = Σ −f_out(k)·v(k)·dt      (k ≤ n, f_out: the force actually sent out)
//
// is the net energy the environment has absorbed from the user since the last reset. A passive
// environment (springs, dampers, starting unloaded) keeps E ≥ 0; E < 0 means the environment
// (here: a local model updated over a network) has handed the user −E joules it never received.
// The controller then adds a damper along the velocity, f_out = f − α·v with
// α = −E/(|v|²·dt), which dissipates exactly that much this cycle and brings E back to 0, bounded
// by `max_damping_n_s_per_m` (the device's damping rating): what a bounded α cannot dissipate
// stays in E and is taken out over the next cycles.
//
// The observer uses this cycle's velocity over the whole cycle (the paper's estimate), so it is a
// discrete-time approximation of the work done; a passive spring's stored-then-returned energy
// sums to zero up to the sampling error, hence `energy_tolerance_j`.
#pragma once

#include "hapsim/core/types.h"

#include <cstdint>

namespace hapsim {

struct PassivityObserverOptions {
  /// False: observe and count only, never change the force (`--force-mode raw` comparisons).
  bool enabled = true;
  /// Bound on the damping the controller adds, N·s/m: the device's rated damping (CHAI3D's
  /// figures are 4–30 N·s/m, core/device_profile.h); far below the 2·m/dt a 0.2 kg device at
  /// 1 kHz could take before the damper itself rings.
  double max_damping_n_s_per_m = 20.0;
  /// The controller acts once the environment has given out more than this (J). The sampled
  /// estimate of a passive spring K dips below zero by up to ½·K·(v·dt)² as it unloads at speed
  /// v, which is sampling, not generation: 10 µJ is a 2000 N/m contact left at 0.1 m/s at 1 kHz
  /// (and 0.05 % of the sweep's 20 mJ budget).
  double energy_tolerance_j = 1e-5;
};

/// What the observer saw and did since construction (reset() keeps these: a health report).
struct PassivityObserverCounts {
  std::uint64_t cycles = 0;
  std::uint64_t acted = 0;      ///< cycles the controller added damping
  std::uint64_t saturated = 0;  ///< of those, cycles α hit its bound
  std::uint64_t nonfinite = 0;  ///< cycles with a non-finite input: zero force sent
  double dissipated_j = 0.0;    ///< energy the controller's damper took out
};

class PassivityObserver {
 public:
  /// Throws hapsim::Error unless max_damping_n_s_per_m and energy_tolerance_j are finite, ≥ 0.
  explicit PassivityObserver(PassivityObserverOptions options = {});

  /// The force to send for this cycle: `f_n` unchanged while the environment has been passive,
  /// with the controller's damper added once it has generated energy; zero for non-finite input
  /// or a non-positive dt. haptic path
  [[nodiscard]] Vec3 filter(const Vec3& f_n, const Vec3& v_m_per_s, double dt_s) noexcept;

  /// Forgets the observed energy (a new contact, a new session); keeps the counts.
  void reset() noexcept { energy_j_ = 0.0; }

  /// Net energy the environment has absorbed since the last reset (J); ≥ −tolerance while the
  /// controller is enabled and α is not saturated.
  [[nodiscard]] double observed_energy_j() const noexcept { return energy_j_; }
  [[nodiscard]] const PassivityObserverCounts& counts() const noexcept { return counts_; }
  [[nodiscard]] const PassivityObserverOptions& options() const noexcept { return options_; }

 private:
  PassivityObserverOptions options_;
  double energy_j_ = 0.0;
  PassivityObserverCounts counts_;
};

}  // namespace hapsim
