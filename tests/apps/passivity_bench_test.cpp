// The passivity sweep's energy accounting against analytic cases: a spring evaluated in
// continuous time stores exactly what it took (E = W + F²/2K stays 0), and a spring sampled at
// period T with a zero-order hold is active, with net damping b − K·T/2 (Colgate & Schenkel 1997):
// stable with the hand's damper above K·T/2, generating energy without bound below it.
#include "bench/passivity_cases.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace hapsim::bench {
namespace {

PortEnvironment spring(double k_n_per_m) {
  return [k_n_per_m](double s_m, double) { return k_n_per_m * std::max(0.0, -s_m); };
}

TEST(PassivityPort, AContinuousSpringGeneratesNoEnergy) {
  PortOptions options;
  options.zero_order_hold = false;
  options.substeps = 200;
  const double k = 1000.0;
  const PortRun run = run_port(spring(k), k, options);
  // The hand presses 1 N: the spring stores 1/(2·1000) J = 0.5 mJ; E stays at zero to within the
  // trapezoid's error across the touch (where the force has a kink).
  EXPECT_NEAR(run.final_depth_m, 1e-3, 1e-6);
  EXPECT_LT(std::abs(run.energy_end_j), 1e-8);
  EXPECT_LT(run.energy_max_j, 1e-8);
  EXPECT_TRUE(run.stable);
  EXPECT_GT(run.peak_force_n, 1.0);  // the fall from 2 mm overshoots the 1 N rest force
}

TEST(PassivityPort, ASampledSpringIsStableWithDampingAboveKTOverTwo) {
  PortOptions options;      // hand damper 2 N s/m
  const double k = 1000.0;  // K·T/2 = 0.5 N s/m
  const PortRun run = run_port(spring(k), k, options);
  EXPECT_TRUE(run.stable);
  EXPECT_NEAR(run.final_depth_m, 1e-3, 1e-6);
  // The hold made the spring active during the fall (E > 0), and the hand's damper took it out.
  EXPECT_GT(run.energy_max_j, 0.0);
  EXPECT_LT(run.late_energy_j, 1e-9);
}

TEST(PassivityPort, ASampledSpringGeneratesEnergyWithDampingBelowKTOverTwo) {
  PortOptions options;
  const double k = 8000.0;  // K·T/2 = 4 N s/m against the hand's 2
  const PortRun run = run_port(spring(k), k, options);
  EXPECT_FALSE(run.stable);
  EXPECT_GT(run.late_energy_j, 1e-3);
  EXPECT_GT(run.energy_end_j, run.late_energy_j);
  // The same spring in continuous time is passive.
  options.zero_order_hold = false;
  EXPECT_TRUE(run_port(spring(k), k, options).stable);
}

}  // namespace
}  // namespace hapsim::bench
