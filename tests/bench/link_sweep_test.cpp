// The network sweep (bench/link_sweep.h) against answers worked out here: the wall's hold is the
// hand spring and the wall spring in series; the tissue's hold and its stored energy come from
// this file's own bisection and quadrature of the force law; raw force must be caught unstable
// at 20 ms and the local model must hold the targets on a reduced grid; an outage fades
// the local model to zero 150 ms after its last model, while raw holds its last force.
#include "bench/link_sweep.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::bench {
namespace {

using net::ForceMode;

const OneDofPlant kPlant{};

std::string name(const LinkCase& c) {
  return std::string(to_string(c.mode)) + " " + environment_name(c.environment) + " " +
         hand_name(c.hand) + " " + std::to_string(static_cast<int>(std::lround(1e3 * c.delay_s))) +
         " ms " + std::to_string(static_cast<int>(std::lround(100.0 * c.loss))) + " %";
}

LinkCase make_case(ForceMode mode, SweepEnvironment environment, SweepHand hand, int delay_ms,
                   double loss) {
  LinkCase c;
  c.mode = mode;
  c.environment = environment;
  c.hand = hand;
  c.delay_s = 1e-3 * delay_ms;
  c.jitter_s = 0.5 * c.delay_s;
  c.loss = loss;
  return c;
}

// The tissue's force law, solved here: where the device is when the contact spring and the
// settled tissue carry f.
double tissue_position_m(double f_n) {
  return kPlant.tissue_y0_m * std::log1p(f_n / kPlant.tissue_a_n) +
         f_n / kPlant.contact_stiffness_n_per_m;
}

template <typename G>
double bisect(G g, double lo, double hi) {
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

double tissue_hold_n(SweepHand hand) {
  const HandModel h = hand_model(hand);
  return bisect(
      [&](double f) { return f - h.stiffness_n_per_m * (h.target_m - tissue_position_m(f)); }, 0.0,
      h.stiffness_n_per_m * h.target_m);
}

double wall_hold_n(SweepHand hand) {
  const HandModel h = hand_model(hand);
  const double k_w = kPlant.wall_stiffness_n_per_m;
  return h.stiffness_n_per_m * k_w / (h.stiffness_n_per_m + k_w) * h.target_m;
}

TEST(LinkSweepModel, AnalyticHoldsAndStorageAgreeWithThisFilesOwn) {
  for (const SweepHand hand : {SweepHand::kRelaxed, SweepHand::kStiff}) {
    EXPECT_NEAR(analytic_hold_force_n(kPlant, SweepEnvironment::kTissue, hand), tissue_hold_n(hand),
                1e-9);
    EXPECT_NEAR(analytic_hold_force_n(kPlant, SweepEnvironment::kWall, hand), wall_hold_n(hand),
                1e-12);
  }
  // The tissue's stored energy at force F is ∫F dx up to the position carrying F (trapezoids on
  // a fine grid of positions, each force by bisection).
  const double f_n = 5.0;
  const double x_m = tissue_position_m(f_n);
  EXPECT_NEAR(quasi_static_force_n(kPlant, SweepEnvironment::kTissue, x_m), f_n, 1e-9);
  const int n = 4000;
  double integral_j = 0.0;
  double previous_n = 0.0;
  for (int i = 1; i <= n; ++i) {
    const double xi = x_m * i / n;
    const double fi = bisect([&](double f) { return tissue_position_m(f) - xi; }, 0.0, 100.0);
    integral_j += 0.5 * (previous_n + fi) * (x_m / n);
    previous_n = fi;
  }
  EXPECT_NEAR(stored_energy_at_force_j(kPlant, SweepEnvironment::kTissue, f_n), integral_j,
              1e-6 * integral_j);
  EXPECT_NEAR(stored_energy_at_force_j(kPlant, SweepEnvironment::kWall, f_n),
              0.5 * f_n * f_n / kPlant.wall_stiffness_n_per_m, 1e-15);
  EXPECT_EQ(stored_energy_at_force_j(kPlant, SweepEnvironment::kWall, -1.0), 0.0);
}

TEST(LinkSweep, WallHoldIsTheHandAndWallSpringsInSeries) {
  for (const ForceMode mode : {ForceMode::kRaw, ForceMode::kLocalModel}) {
    for (const SweepHand hand : {SweepHand::kRelaxed, SweepHand::kStiff}) {
      const LinkCase c = make_case(mode, SweepEnvironment::kWall, hand, 0, 0.0);
      const LinkRun r = run_link_case(c);
      EXPECT_NEAR(r.steady_force_n, wall_hold_n(hand), 1e-4 * wall_hold_n(hand)) << name(c);
      EXPECT_TRUE(r.stable) << name(c);
    }
  }
  // The local model holds it through 100 ms and 30 % loss too.
  const LinkCase c =
      make_case(ForceMode::kLocalModel, SweepEnvironment::kWall, SweepHand::kStiff, 100, 0.3);
  EXPECT_NEAR(run_link_case(c).steady_force_n, wall_hold_n(SweepHand::kStiff),
              1e-4 * wall_hold_n(SweepHand::kStiff));
}

TEST(LinkSweep, RawForceIsCaughtUnstableAtTwentyMilliseconds) {
  for (const SweepEnvironment environment : {SweepEnvironment::kTissue, SweepEnvironment::kWall}) {
    for (const SweepHand hand : {SweepHand::kRelaxed, SweepHand::kStiff}) {
      // Without delay raw force holds the analytic force: the detector is not simply always on.
      const LinkCase held = make_case(ForceMode::kRaw, environment, hand, 0, 0.0);
      const LinkRun h = run_link_case(held);
      EXPECT_TRUE(h.stable) << name(held);
      const double hold_n =
          environment == SweepEnvironment::kTissue ? tissue_hold_n(hand) : wall_hold_n(hand);
      EXPECT_NEAR(h.steady_force_n, hold_n, 1e-3 * hold_n) << name(held);

      const LinkCase c = make_case(ForceMode::kRaw, environment, hand, 20, 0.0);
      const LinkRun r = run_link_case(c);
      EXPECT_FALSE(r.stable) << name(c);
      // A limit cycle: the force swings by more than half the hold and feeds energy in.
      EXPECT_GT(r.hold_ripple_rms_n, 0.5 * hold_n) << name(c);
      EXPECT_GT(r.hold_work_j, 0.0) << name(c);
      EXPECT_GT(r.energy_generated_j, 1.0) << name(c);
    }
  }
}

// The targets on a reduced grid (the full grid is `hapsim bench network`). One known
// miss, in docs/benchmarks.md#network: the stiff hand on the stiffening tissue from 50 ms, where
// the linear model is a round trip stale during the press (about 26 mJ, not < 20 mJ).
TEST(LinkSweep, LocalModelMeetsItsTargetsOnAReducedGrid) {
  LinkSweepOptions options;
  options.modes = {ForceMode::kLocalModel};
  options.delays_ms = {0, 20, 100};
  options.losses = {0.0, 0.3};
  options.outage_s = 0.0;
  const std::vector<LinkSweepRow> rows = run_link_sweep(options);
  ASSERT_EQ(rows.size(), 2u * 2u * 3u * 2u);
  for (const LinkSweepRow& row : rows) {
    const LinkCase& c = row.link_case;
    SCOPED_TRACE(name(c));
    const LinkRun& r = row.run;
    const double hold_n =
        c.environment == SweepEnvironment::kTissue ? tissue_hold_n(c.hand) : wall_hold_n(c.hand);
    EXPECT_TRUE(r.stable);
    EXPECT_NEAR(r.steady_force_n, hold_n, 0.01 * hold_n);
    EXPECT_LT(std::abs(row.steady_force_error), 0.05);
    EXPECT_LT(r.hold_ripple_rms_n, 0.05);
    EXPECT_LE(r.peak_force_n, kPlant.max_force_n);
    EXPECT_LT(r.energy_generated_j, 0.020);
    // Every reordered sample was refused by sequence, and nothing else was refused.
    EXPECT_EQ(r.refused_out_of_order, r.reordered);
    EXPECT_EQ(r.refused_other, 0u);
    if (c.delay_s > 0.0) {
      EXPECT_GT(r.reordered, 0u);  // jitter U[0, d/2] at 1 kHz reorders
    }
  }
}

// A linear model a round trip old is too soft on a stiffening tissue for the depth the device has
// reached since: the stiff hand's press at 100 ms generates energy beyond the 20 mJ target
// without the tissue's profile, and far less with it.
TEST(LinkSweep, TheTissuesProfileIsWhatKeepsALongLinkFromGeneratingEnergy) {
  LinkCase c =
      make_case(ForceMode::kLocalModel, SweepEnvironment::kTissue, SweepHand::kStiff, 100, 0.0);
  const LinkRun with_profile = run_link_case(c);
  c.tissue_profile = false;
  const LinkRun linear = run_link_case(c);
  EXPECT_GT(linear.energy_generated_j, 0.020);
  EXPECT_LT(with_profile.energy_generated_j, 0.020);
  EXPECT_LT(with_profile.energy_generated_j, 0.5 * linear.energy_generated_j);
  EXPECT_TRUE(with_profile.stable);
  EXPECT_NEAR(with_profile.steady_force_n, tissue_hold_n(c.hand), 0.01 * tissue_hold_n(c.hand));
}

TEST(LinkSweep, OutageFadesTheLocalModelToZeroAndRawHoldsItsLastForce) {
  for (const SweepEnvironment environment : {SweepEnvironment::kTissue, SweepEnvironment::kWall}) {
    LinkCase c = make_case(ForceMode::kLocalModel, environment, SweepHand::kRelaxed, 20, 0.0);
    c.outage_start_s = 3.0;
    c.outage_s = 0.3;
    const LinkRun r = run_link_case(c);
    SCOPED_TRACE(name(c));
    // 100 ms stale + 50 ms fade after the last model the device received, which came at the
    // latest as the link went down (what was on the wire then is lost with it).
    ASSERT_GE(r.outage_force_zero_after_last_model_s, 0.0);
    EXPECT_LE(r.outage_force_zero_after_last_model_s, 0.150 + 1e-9);
    EXPECT_GE(r.outage_force_zero_after_last_model_s, 0.140);
    EXPECT_LE(r.outage_force_zero_s, 0.150 + 1e-9);
    // The model comes back and holds again.
    EXPECT_TRUE(r.stable);
    const double hold_n =
        environment == SweepEnvironment::kTissue ? tissue_hold_n(c.hand) : wall_hold_n(c.hand);
    EXPECT_NEAR(r.steady_force_n, hold_n, 0.01 * hold_n);

    c.mode = ForceMode::kRaw;
    c.delay_s = 0.0;  // raw holds at 0 ms: what it does in an outage is its own
    c.jitter_s = 0.0;
    const LinkRun raw = run_link_case(c);
    EXPECT_LT(raw.outage_force_zero_s, 0.0) << "raw mode holds its last force through an outage";
  }
}

TEST(LinkSweep, SameSeedSameRunAndTheSeedMovesOnlyTheDraws) {
  LinkCase c =
      make_case(ForceMode::kLocalModel, SweepEnvironment::kTissue, SweepHand::kRelaxed, 20, 0.3);
  const LinkRun a = run_link_case(c);
  const LinkRun b = run_link_case(c);
  EXPECT_EQ(a.steady_force_n, b.steady_force_n);
  EXPECT_EQ(a.energy_generated_j, b.energy_generated_j);
  EXPECT_EQ(a.lost, b.lost);
  c.seed = 7;
  const LinkRun other = run_link_case(c);
  EXPECT_NE(other.lost, a.lost);
  EXPECT_NEAR(other.steady_force_n, a.steady_force_n, 1e-3 * a.steady_force_n);
}

TEST(LinkSweep, SweepRowsCompareTheLocalModelWithItsZeroDelayRun) {
  LinkSweepOptions options = quick_link_sweep_options();
  options.environments = {SweepEnvironment::kWall};
  options.hands = {SweepHand::kRelaxed};
  options.delays_ms = {20};  // no zero-delay row in the grid: the sweep runs its own
  options.losses = {0.0};
  int progress_calls = 0;
  double last_fraction = -1.0;
  options.progress = [&](std::string_view, double fraction) {
    ++progress_calls;
    EXPECT_GE(fraction, last_fraction);
    last_fraction = fraction;
  };
  const std::vector<LinkSweepRow> rows = run_link_sweep(options);
  ASSERT_EQ(rows.size(), 2u + 2u);  // raw and local model, then an outage row each
  EXPECT_EQ(last_fraction, 1.0);
  EXPECT_GT(progress_calls, 0);
  for (const LinkSweepRow& row : rows) {
    SCOPED_TRACE(name(row.link_case));
    EXPECT_NEAR(row.analytic_force_n, wall_hold_n(SweepHand::kRelaxed), 1e-12);
    if (row.link_case.mode == ForceMode::kRaw) {
      EXPECT_EQ(row.reference_force_n, row.analytic_force_n);
    } else {
      EXPECT_NEAR(row.reference_force_n, wall_hold_n(SweepHand::kRelaxed), 1e-4);
    }
    EXPECT_NEAR(row.steady_force_error,
                (row.run.steady_force_n - row.reference_force_n) / row.reference_force_n, 1e-12);
  }
  EXPECT_FALSE(rows[0].is_outage());
  EXPECT_TRUE(rows[3].is_outage());
}

}  // namespace
}  // namespace hapsim::bench
