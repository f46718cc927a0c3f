// The passivity sweep (issue 14 item 4, `hapsim bench passivity`): each shipped device profile
// rendering a plane, a sphere, the virtual sheet, the knee and a FEM block at 1.0x and 1.5x its
// rated stiffness, held by a simulated device and hand; the energy the rendering generated at the
// device port, and the largest stiffness that stays stable (the profile's Z-width) beside its
// rating.
//
// The port (one axis, along the surface normal at the pressed point): the device's apparent mass
// m and a hand, a spring k_h and damper b_h from an anchor below the surface, so at rest the hand
// presses with `hand_press_n`. The handle starts `start_gap_m` above the surface at rest, falls in
// and is held there for the run. The environment is sampled at 1 kHz and its force held between
// samples (zero-order hold, as a device does); the mechanics between samples are integrated in
// `substeps` steps. Energy generated at the port: E(t) = W(t) + U(t), W the work the rendered force
// did on the device (exact under the hold: F·Δx per sample) and U = F²/2K what an ideal spring of
// the rendered stiffness K would store at the force rendered now; E ≤ 0 for a passive environment.
#pragma once

#include "hapsim/core/progress.h"

#include <atomic>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace hapsim::bench {

struct PortOptions {
  double device_mass_kg = 0.1;
  double hand_stiffness_n_per_m = 200.0;
  double hand_damping_n_s_per_m = 2.0;
  double hand_press_n = 1.0;
  double start_gap_m = 0.002;
  double duration_s = 10.0;
  double sample_period_s = 0.001;
  int substeps = 50;
  /// False: the environment is evaluated at every substep (a continuous-time environment; the
  /// energy accounting's reference case).
  bool zero_order_hold = true;
  /// Stable: E grew by at most this over the second half of the run...
  double late_energy_threshold_j = 1e-4;
  /// ...and the handle moved at most this (peak to peak) over the last second.
  double late_motion_threshold_m = 1e-4;
};

/// The environment's push along the port's axis (N, positive out of the surface) with the handle
/// at height s_m above the surface's first touch (negative: pressed in) at time t_s.
using PortEnvironment = std::function<double(double s_m, double t_s)>;

struct PortRun {
  double energy_end_j = 0.0;   ///< E at the end of the run
  double energy_max_j = 0.0;   ///< the largest E over the run
  double late_energy_j = 0.0;  ///< E(end) − E(half way)
  double late_motion_m = 0.0;  ///< peak-to-peak over the last second
  double final_depth_m = 0.0;  ///< −s at the end
  double peak_force_n = 0.0;
  bool stable = false;
};

/// Runs the port against `environment`, whose stored energy is that of a spring of
/// `stiffness_n_per_m` at the force rendered.
[[nodiscard]] PortRun run_port(const PortEnvironment& environment, double stiffness_n_per_m,
                               const PortOptions& options);

struct PassivityOptions {
  /// Profiles to run (default: every shipped profile).
  std::vector<std::string> profiles;
  /// "plane", "sphere", "sheet", "knee", "fem" (default: all). "fem": the FEM block of `hapsim
  /// bench fem` (bench/fem_cases.h; about 1k tets, corotational, backward Euler at 100 Hz)
  /// through the world's local contact model, pressed at its top's centre.
  std::vector<std::string> surfaces;
  std::filesystem::path scenes_dir;
  PortOptions port;
  /// Bisection steps on the stiffness for the Z-width (0: no Z-width).
  int bisection_steps = 8;
  ProgressFn progress;
  /// Set (by SIGINT or SIGTERM) to end the bench after the row under way: the rows done are
  /// returned. Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
};

struct PassivityRow {
  std::string profile;
  std::string surface;
  double rated_stiffness_n_per_m = 0.0;
  double factor = 1.0;  ///< of the rated stiffness
  double device_mass_kg = 0.0;
  PortRun run;
  /// The K of the energy's F²/2K: the material's stiffness (factor × rated), or for the FEM
  /// block the series stiffness it renders (contact spring and tissue), which is smaller.
  double port_stiffness_n_per_m = 0.0;
};

struct ZWidthRow {
  std::string profile;
  std::string surface;
  double rated_stiffness_n_per_m = 0.0;
  /// The largest stable stiffness found (bisection between 1/64 and 64x the rating); 0 when even
  /// the lowest is unstable.
  double max_stable_stiffness_n_per_m = 0.0;
  bool above_search = false;  ///< stable at 64x the rating (the search's top)
};

struct PassivityResult {
  std::vector<PassivityRow> rows;
  std::vector<ZWidthRow> z_width;
};

[[nodiscard]] PassivityResult run_passivity_sweep(const PassivityOptions& options);
[[nodiscard]] std::string format_passivity_table(const PassivityResult& result);
[[nodiscard]] nlohmann::json passivity_to_json(const PassivityResult& result);

}  // namespace hapsim::bench
