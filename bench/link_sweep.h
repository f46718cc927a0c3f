// The issue-12 network sweep (`hapsim bench network`, docs/benchmarks.md#network): a 1-DOF
// fingertip pressing an environment through a simulated link, with the force closed either the
// paper's way (raw) or through the local contact model (SPEC §8), so their stability, accuracy
// and energy can be compared over delay, loss, jitter and an outage. A plain simulation,
// deterministic for a seed, no clock. A benchmark, not part of the net library: it lives in the
// bench cases (hapsim_bench_cases, not installed) and uses the net layer's codecs, gates and
// LinkShim as a device host and serve use them; the 1-DOF plant below is its own (no library
// code uses it).
//
// The plant (one cycle = 1 ms, semi-implicit Euler): a 0.2 kg device held by a hand, a spring
// and damper pulling it towards a target. Penetration runs along +x, the environment pushes
// back along −x. The device starts 5 mm above the surface at rest; the hand holds it there for
// 0.5 s while the link fills (a session is running before anyone touches anything), then moves
// its target 25 mm in, to 20 mm below the surface, in 0.3 s (minimum jerk: a press, peak 0.16
// m/s; `approach_s` = 0 is a step, the slam of tests/bench/local_model_1dof_test.cpp).
// Environments (both with 1 N·s/m of contact damping):
//  * tissue: a 2000 N/m contact spring in series with stiffening tissue a·(exp(y/y0) − 1)
//    (200 N/m at first touch, ~860 N/m at the relaxed hold), the tissue's depth driven by the
//    force the device actually rendered (SPEC §8);
//  * wall: a 1000 N/m wall.
// Hands:
//  * relaxed: 300 N/m, 2 N·s/m (damping ratio 0.13 on the device alone, 0.08 in contact);
//  * stiff: 1200 N/m, 6 N·s/m — a co-contracted grip: four times stiffer, the damping scaled with
//    √k (co-contraction raises both) and a little more (ratio 0.19). It holds 7 N on the tissue
//    and 11 N on the wall.
// The link: a net::LinkShim each way with one-way delay d, i.i.d. loss, jitter U[0, d/2]
// (samples overtake each other) and optionally an outage in both directions. What crosses it is
// the wire format (hapsim_msg_DeviceState up, hapsim_msg_LocalModel down) through the real gates,
// so late and reordered samples are refused by sequence as a device host refuses them.
// Modes:
//  * raw: the simulation answers each device state with the quasi-static force at the position
//    it heard of (contact and tissue settled) plus the contact damping; the device holds the
//    newest force it received. The paper's way, unsafe beyond a few ms; no observer (it is the
//    reference for what goes wrong).
//  * local-model: the simulation sends f0, x0, v0 and K = contact in series with the tissue at
//    its current depth (force/local_contact_model.h); the device renders it from its own fresh
//    state through LocalModelRenderer (20 ms blend, 100 ms stale + 50 ms fade by its own receive
//    clock), then the PassivityObserver.
//
// What a run reports:
//  * steady_force_n, hold_ripple_rms_n: the rendered force's mean and rms about it over the last
//    second; peak_force_n: the largest |force| rendered.
//  * energy_generated_j: passivity against the ideal environment's storage function S (the
//    energy the same springs, settled, hold when they carry force F). With W(t) the work the
//    rendered force has done on the device (exact per Euler step), an environment is passive
//    when what it took in covers what it holds, −W(t) ≥ S(F(t)), so
//        energy_generated = max over the run of W(t) + S(F(t)), and 0 if that stays ≤ 0:
//    what the force has given the device plus what it could still give back, beyond what it
//    was given. A limit cycle adds its cycle integral every period; a force that comes back at
//    depth after an outage adds the energy it then holds; a model too soft for a while (a
//    stale linearisation on a stiffening tissue) and then right adds what the right one holds
//    beyond what the soft one took in. `energy_out_j` is max W(t) alone, the textbook
//    one-port measure (no credit for storage), which the observer bounds.
//  * stable: the force has settled — ripple over the last second below 10 % of the analytic
//    hold force — and the rendered force did no net positive work on the device over that
//    second (≤ 1 mJ): a limit cycle fails both, a slow drift the first.
//  * for an outage: the time from the outage's start, and from the arrival of the last model
//    before it (when the device's feed stops: the stale + fade rule counts from there), to the
//    first cycle from which the force stays below 0.01 N to the outage's end.
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/device/local_model_renderer.h"
#include "hapsim/device/passivity_observer.h"
#include "hapsim/net/force_mode.h"

#include <cstdint>
#include <string>
#include <vector>

namespace hapsim::bench {

enum class SweepEnvironment : std::uint8_t { kTissue, kWall };
enum class SweepHand : std::uint8_t { kRelaxed, kStiff };
/// Which K the simulation sends in local-model mode: the whole contact's (contact spring in
/// series with the tissue: the right one) or the contact spring's alone (an analysis case: its
/// error comes back through the tissue each round trip).
enum class ModelStiffness : std::uint8_t { kSeries, kContactOnly };

[[nodiscard]] const char* environment_name(SweepEnvironment environment) noexcept;
[[nodiscard]] const char* hand_name(SweepHand hand) noexcept;

/// The 1-DOF plant every run shares.
struct OneDofPlant {
  double dt_s = 0.001;
  double device_mass_kg = 0.2;
  double start_m = -0.005;  ///< 5 mm above the surface, at rest
  double contact_stiffness_n_per_m = 2000.0;
  double contact_damping_n_s_per_m = 1.0;
  /// Tissue f_t(y) = a·(exp(y/y0) − 1): 200 N/m at first touch, ~860 N/m at the relaxed hold.
  double tissue_a_n = 1.0;
  double tissue_y0_m = 0.005;
  double wall_stiffness_n_per_m = 1000.0;
  double max_force_n = 20.0;
  double validity_radius_m = 0.05;
};

struct HandModel {
  double stiffness_n_per_m = 0.0;
  double damping_n_s_per_m = 0.0;
  /// Where the hand would put the fingertip (metres into the surface).
  double target_m = 0.0;
};
[[nodiscard]] HandModel hand_model(SweepHand hand) noexcept;

/// One run.
struct LinkCase {
  net::ForceMode mode = net::ForceMode::kLocalModel;
  SweepEnvironment environment = SweepEnvironment::kTissue;
  SweepHand hand = SweepHand::kRelaxed;
  double delay_s = 0.0;  ///< one-way, both directions
  double jitter_s = 0.0;
  double loss = 0.0;  ///< i.i.d., both directions
  /// Both directions lose everything sent in [start, start + length). Negative start: none.
  double outage_start_s = -1.0;
  double outage_s = 0.0;
  /// Simulated seconds; 0: default_duration_s(delay_s, jitter_s) (plus the outage).
  double duration_s = 0.0;
  /// The hand holds the device at rest at the start while the link fills, then moves its target
  /// in at `approach_start_s` over `approach_s` (minimum jerk; 0: a step).
  double approach_start_s = 0.5;
  double approach_s = 0.3;
  bool passivity_observer = true;  ///< local-model mode only
  PassivityObserverOptions observer;
  /// The device side's renderer (max_force_n comes from the plant).
  double blend_s = 0.02;
  double stale_after_s = 0.1;
  double fade_s = 0.05;
  double reengage_s = 0.5;
  ModelStiffness model_stiffness = ModelStiffness::kSeries;
  /// The tissue's models carry how it stiffens along the normal (LocalContactModel's profile);
  /// false: the linear model alone (K at the tissue's current depth).
  bool tissue_profile = true;
  std::uint64_t seed = 1;
  OneDofPlant plant;
};

struct LinkRun {
  double duration_s = 0.0;
  double steady_force_n = 0.0;
  double hold_ripple_rms_n = 0.0;
  double peak_force_n = 0.0;
  double energy_generated_j = 0.0;
  /// The textbook passivity measure alone: the largest net work the rendered force did on the
  /// device, max over t of W(t) (no credit for storage). What the observer estimates and bounds.
  double energy_out_j = 0.0;
  /// The work the rendered force did on the device over the last second (> 0: it fed energy in).
  double hold_work_j = 0.0;
  bool stable = false;
  /// Seconds from the outage's start (or from the last model received before it) to the first
  /// cycle with |force| < 0.01 N; negative when there is no outage or the force never got there.
  double outage_force_zero_s = -1.0;
  double outage_force_zero_after_last_model_s = -1.0;
  PassivityObserverCounts observer;
  std::uint64_t models_accepted = 0;       ///< local models, or raw forces, the device applied
  std::uint64_t refused_out_of_order = 0;  ///< by the device (models) and the simulation (states)
  std::uint64_t refused_other = 0;         ///< any other verdict (none expected: a harness check)
  std::uint64_t lost = 0;                  ///< by the links, both ways
  std::uint64_t reordered = 0;             ///< delivered after a later sample, both ways
};

/// 4.5 s, or 2.5 s plus 20 round trips for long links (the local model converges once per round
/// trip), whichever is longer.
[[nodiscard]] double default_duration_s(double delay_s, double jitter_s) noexcept;

[[nodiscard]] LinkRun run_link_case(const LinkCase& link_case);

/// The ideal environment's force at device position x (the contact and tissue settled: what a
/// simulation of the whole contact answers for a position), and the energy it stores when it
/// carries `force_n` (its storage function; 0 for no push).
[[nodiscard]] double quasi_static_force_n(const OneDofPlant& plant, SweepEnvironment environment,
                                          double x_m) noexcept;
[[nodiscard]] double stored_energy_at_force_j(const OneDofPlant& plant,
                                              SweepEnvironment environment,
                                              double force_n) noexcept;
/// The hold the ideal environment settles to under the hand: k_h·(target − x) = F(x).
[[nodiscard]] double analytic_hold_force_n(const OneDofPlant& plant, SweepEnvironment environment,
                                           SweepHand hand) noexcept;

struct LinkSweepOptions {
  std::vector<net::ForceMode> modes{net::ForceMode::kRaw, net::ForceMode::kLocalModel};
  std::vector<SweepEnvironment> environments{SweepEnvironment::kTissue, SweepEnvironment::kWall};
  std::vector<SweepHand> hands{SweepHand::kRelaxed, SweepHand::kStiff};
  std::vector<int> delays_ms{0, 5, 20, 50, 100};
  std::vector<double> losses{0.0, 0.1, 0.3};
  /// Jitter U[0, jitter_fraction·delay].
  double jitter_fraction = 0.5;
  /// One outage row per (mode, environment, hand) at this delay, loss 0; outage_s ≤ 0: none.
  int outage_delay_ms = 20;
  double outage_s = 0.3;
  double outage_start_s = 3.0;  ///< during the hold
  /// The hand's approach and the renderer's blend (LinkCase::approach_s, blend_s).
  double approach_s = 0.3;
  double blend_s = 0.02;
  /// False: the local model without its passivity observer (to see what the observer does).
  bool passivity_observer = true;
  std::uint64_t seed = 1;
  ProgressFn progress;
};

/// A smaller grid for tests and `--quick`: delays 0, 20, 100 ms, losses 0 and 30 %.
[[nodiscard]] LinkSweepOptions quick_link_sweep_options();

struct LinkSweepRow {
  LinkCase link_case;
  LinkRun run;
  /// What steady_force_error compares with: the zero-delay, loss-free run of the same mode,
  /// environment and hand (local model), the analytic hold (raw).
  double reference_force_n = 0.0;
  double analytic_force_n = 0.0;
  /// (steady − reference) / reference.
  double steady_force_error = 0.0;
  [[nodiscard]] bool is_outage() const noexcept { return link_case.outage_start_s >= 0.0; }
};

/// Every (mode, environment, hand, delay, loss) of the grid, then the outage rows.
[[nodiscard]] std::vector<LinkSweepRow> run_link_sweep(const LinkSweepOptions& options);

}  // namespace hapsim::bench
