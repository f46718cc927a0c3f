// The issue-12 analysis as a test: a 1-DOF fingertip (device 0.2 kg held by a 300 N/m hand)
// presses a 2000 N/m contact spring on stiffening tissue, with the simulation on the far side of
// a link with one-way delay and i.i.d. loss both ways. Three ways of closing the loop, run by
// the sweep's model (bench/link_sweep.h) with the hand's target stepped in at once and no
// passivity observer, so what is measured is the closing alone:
//  * raw force: the simulation sends the force at the position it last heard of;
//  * local model, K = contact in series with tissue: the device renders f0 + K·(x − x0) itself;
//  * local model, K = contact stiffness alone.
// The steady force is checked against the analytic equilibrium (hand spring = contact spring =
// tissue force, solved by bisection here, not by simulating), and oscillation by the force's
// rms about its mean over the last second.
#include "bench/link_sweep.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace hapsim::bench {
namespace {

using net::ForceMode;

const OneDofPlant kPlant{};
constexpr double kHandStiffness_n_per_m = 300.0;
constexpr double kHandTarget_m = 0.02;

double tissue_force_n(double y_m) {
  return kPlant.tissue_a_n * (std::exp(y_m / kPlant.tissue_y0_m) - 1.0);
}
double tissue_stiffness_n_per_m(double y_m) {
  return kPlant.tissue_a_n / kPlant.tissue_y0_m * std::exp(y_m / kPlant.tissue_y0_m);
}
double tissue_depth_m(double force_n) {
  return kPlant.tissue_y0_m * std::log1p(std::max(force_n, 0.0) / kPlant.tissue_a_n);
}

// Where the device must be for the contact to carry `force_n` (tissue settled under it).
double position_for_force_m(double force_n) {
  return tissue_depth_m(force_n) + force_n / kPlant.contact_stiffness_n_per_m;
}

// Bisection on an increasing function g with g(lo) <= 0 <= g(hi).
template <typename G>
double bisect(G g, double lo, double hi) {
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

// The analytic hold: the hand spring's force equals the contact's, F = k_h·(x_h − x(F)).
double analytic_steady_force_n() {
  return bisect(
      [](double f) {
        return f - kHandStiffness_n_per_m * (kHandTarget_m - position_for_force_m(f));
      },
      0.0, kHandStiffness_n_per_m * kHandTarget_m);
}

// Quasi-static contact force at device position x (tissue settled under the contact spring).
double quasi_static_force_n(double x_m) {
  if (x_m <= 0.0) {
    return 0.0;
  }
  return bisect([x_m](double f) { return position_for_force_m(f) - x_m; }, 0.0,
                kPlant.contact_stiffness_n_per_m * x_m);
}

enum class Mode { kRaw, kLocalSeries, kLocalContact };

const char* name(Mode mode) {
  switch (mode) {
    case Mode::kRaw:
      return "raw";
    case Mode::kLocalSeries:
      return "local-series-K";
    case Mode::kLocalContact:
      return "local-contact-K";
  }
  return "?";
}

struct Case {
  Mode mode;
  int delay_ms;
  double loss;
};

// The hold reached, oscillating or not, is written out so the table in the report comes from
// the test itself.
LinkRun run_and_print(const Case& c) {
  LinkCase link;
  link.mode = c.mode == Mode::kRaw ? ForceMode::kRaw : ForceMode::kLocalModel;
  link.model_stiffness =
      c.mode == Mode::kLocalContact ? ModelStiffness::kContactOnly : ModelStiffness::kSeries;
  link.environment = SweepEnvironment::kTissue;
  link.hand = SweepHand::kRelaxed;
  link.delay_s = 1e-3 * c.delay_ms;
  link.loss = c.loss;
  link.approach_start_s = 0.0;  // the hand's target steps in at once, with no model yet
  link.approach_s = 0.0;
  link.passivity_observer = false;
  link.duration_s = c.delay_ms >= 100 ? 8.0 : 4.0;
  const LinkRun r = run_link_case(link);
  const double f_star = analytic_steady_force_n();
  std::printf(
      "1dof %-16s delay %3d ms loss %2.0f %%: mean %.4f N (error %+.2e %%), ripple %.2e N rms, "
      "peak %.2f N\n",
      name(c.mode), c.delay_ms, c.loss * 100.0, r.steady_force_n,
      (r.steady_force_n - f_star) / f_star * 100.0, r.hold_ripple_rms_n, r.peak_force_n);
  return r;
}

class OneDofLink : public ::testing::TestWithParam<Case> {};

TEST(OneDofAnalysis, AnalyticHoldIsConsistent) {
  const double f = analytic_steady_force_n();
  // Hand spring, contact spring and tissue carry the same force at the hold.
  const double x = position_for_force_m(f);
  EXPECT_NEAR(kHandStiffness_n_per_m * (kHandTarget_m - x), f, 1e-9);
  EXPECT_NEAR(tissue_force_n(tissue_depth_m(f)), f, 1e-9);
  EXPECT_NEAR(quasi_static_force_n(x), f, 1e-9);
  // The tissue is softer than the contact at the hold: the regime where K matters.
  EXPECT_LT(tissue_stiffness_n_per_m(tissue_depth_m(f)), kPlant.contact_stiffness_n_per_m);
  // The model under test uses this file's plant and hand.
  EXPECT_EQ(hand_model(SweepHand::kRelaxed).stiffness_n_per_m, kHandStiffness_n_per_m);
  EXPECT_EQ(hand_model(SweepHand::kRelaxed).target_m, kHandTarget_m);
  for (const double x_m : {-0.001, 0.002, 0.01, 0.02}) {
    EXPECT_NEAR(bench::quasi_static_force_n(kPlant, SweepEnvironment::kTissue, x_m),
                quasi_static_force_n(x_m), 1e-9);
  }
}

TEST_P(OneDofLink, LocalModelWithSeriesStiffnessHoldsTheAnalyticForce) {
  const Case c = GetParam();
  const LinkRun r = run_and_print({Mode::kLocalSeries, c.delay_ms, c.loss});
  const double f_star = analytic_steady_force_n();
  EXPECT_NEAR(r.steady_force_n, f_star, 0.01 * f_star);
  EXPECT_LT(r.hold_ripple_rms_n, 0.05);
  EXPECT_LE(r.peak_force_n, kPlant.max_force_n);
}

// Oscillating: the force swings by more than a tenth of the hold over the last second.
TEST_P(OneDofLink, RawForceIsUnstableFromFiveMilliseconds) {
  const Case c = GetParam();
  const LinkRun r = run_and_print({Mode::kRaw, c.delay_ms, c.loss});
  if (c.delay_ms >= 5) {
    EXPECT_GT(r.hold_ripple_rms_n, 0.1 * analytic_steady_force_n());
  }
}

// With the contact stiffness alone the model's error returns through the tissue with gain
// k_c/k_tissue (2.3 at the hold) every round trip. The 20 ms blend low-passes that loop enough
// to hold at 0 ms and at 5 ms without loss (printed, not asserted); from 20 ms it oscillates.
TEST_P(OneDofLink, ContactOnlyModelIsUnstableFromTwentyMilliseconds) {
  const Case c = GetParam();
  const LinkRun r = run_and_print({Mode::kLocalContact, c.delay_ms, c.loss});
  if (c.delay_ms >= 20) {
    EXPECT_GT(r.hold_ripple_rms_n, 0.1 * analytic_steady_force_n());
  }
}

TEST(OneDofLink, RawForceHoldsWithoutDelay) {
  const LinkRun r = run_and_print({Mode::kRaw, 0, 0.0});
  const double f_star = analytic_steady_force_n();
  EXPECT_NEAR(r.steady_force_n, f_star, 0.01 * f_star);
  EXPECT_LT(r.hold_ripple_rms_n, 0.05);
}

std::vector<Case> sweep() {
  std::vector<Case> cases;
  for (const int delay_ms : {0, 5, 20, 200}) {
    for (const double loss : {0.0, 0.1, 0.3}) {
      cases.push_back({Mode::kLocalSeries, delay_ms, loss});
    }
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(DelayAndLoss, OneDofLink, ::testing::ValuesIn(sweep()),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return "delay" + std::to_string(param.param.delay_ms) + "ms_loss" +
                                  std::to_string(static_cast<int>(param.param.loss * 100.0)) +
                                  "pct";
                         });

}  // namespace
}  // namespace hapsim::bench
