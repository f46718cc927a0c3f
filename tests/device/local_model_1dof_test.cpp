// The issue-12 analysis as a test: a 1-DOF fingertip (device 0.2 kg held by a 300 N/m hand)
// presses a 2000 N/m contact spring on stiffening tissue, with the simulation on the far side of
// a link with one-way delay and i.i.d. loss both ways. Three ways of closing the loop:
//  * raw force: the simulation sends the force at the position it last heard of;
//  * local model, K = contact in series with tissue: the device renders f0 + K·(x − x0) itself;
//  * local model, K = contact stiffness alone.
// The steady force is checked against the analytic equilibrium (hand spring = contact spring =
// tissue force, solved by bisection here, not by simulating), and oscillation by the force's
// rms about its mean over the last second.
#include "hapsim/device/local_model_renderer.h"
#include "hapsim/force/local_contact_model.h"
#include "hapsim/net/link_shim.h"

#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

constexpr double kDt_s = 0.001;
constexpr double kDeviceMass_kg = 0.2;
constexpr double kHandStiffness_n_per_m = 300.0;
constexpr double kHandDamping_n_s_per_m = 2.0;  // a relaxed hand: damping ratio ~0.08
constexpr double kHandTarget_m = 0.02;          // where the hand would put the fingertip
constexpr double kContactStiffness_n_per_m = 2000.0;
constexpr double kContactDamping_n_s_per_m = 1.0;
// Stiffening tissue f_t(y) = a·(exp(y/y0) − 1): 200 N/m at first touch, ~860 N/m at the hold.
constexpr double kTissueA_n = 1.0;
constexpr double kTissueY0_m = 0.005;
constexpr double kMaxForce_n = 20.0;
constexpr double kStart_m = -0.005;  // 5 mm above the surface, at rest

double tissue_force_n(double y_m) {
  return kTissueA_n * (std::exp(y_m / kTissueY0_m) - 1.0);
}
double tissue_stiffness_n_per_m(double y_m) {
  return kTissueA_n / kTissueY0_m * std::exp(y_m / kTissueY0_m);
}
double tissue_depth_m(double force_n) {
  return kTissueY0_m * std::log1p(std::max(force_n, 0.0) / kTissueA_n);
}

// Where the device must be for the contact to carry `force_n` (tissue settled under it).
double position_for_force_m(double force_n) {
  return tissue_depth_m(force_n) + force_n / kContactStiffness_n_per_m;
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

// Quasi-static contact force at device position x (tissue settled under the contact spring):
// what a simulation of the whole contact answers for a position.
double quasi_static_force_n(double x_m) {
  if (x_m <= 0.0) {
    return 0.0;
  }
  return bisect([x_m](double f) { return position_for_force_m(f) - x_m; }, 0.0,
                kContactStiffness_n_per_m * x_m);
}

enum class Mode { kRaw, kLocalSeries, kLocalContact };

struct DeviceState {
  double x_m = 0.0;
  double v_m_per_s = 0.0;
  double rendered_n = 0.0;
  std::uint64_t sequence = 0;
};

struct Downlink {
  LocalContactModel model;   // local modes
  double raw_force_n = 0.0;  // raw mode
};

struct RunResult {
  double mean_force_n = 0.0;  // over the last second
  double ripple_rms_n = 0.0;  // rms about that mean
  double peak_force_n = 0.0;
};

// Penetration runs along world +x; the surface's outward normal is −x.
const Vec3 kIn = Vec3::UnitX();

LocalContactModel local_model(const DeviceState& s, double k_n_per_m, std::uint64_t sequence) {
  // The simulation's tissue follows the force the device actually rendered (SPEC §8).
  const double y_m = tissue_depth_m(s.rendered_n);
  const double f0_n =
      tissue_coupled_force_n(s.rendered_n, s.x_m - y_m, kContactStiffness_n_per_m, k_n_per_m);
  LocalContactModel m;
  m.x0_world_m = s.x_m * kIn;
  m.v0_world_m_per_s = s.v_m_per_s * kIn;
  m.f0_world_n = -f0_n * kIn;
  m.stiffness_n_per_m = k_n_per_m * kIn * kIn.transpose();
  m.damping_n_s_per_m = kContactDamping_n_s_per_m * kIn * kIn.transpose();
  m.normal_world = -kIn;
  m.validity_radius_m = 0.05;
  m.sequence = sequence;
  m.device_sequence = s.sequence;
  m.valid = true;
  return m;
}

RunResult simulate(Mode mode, int delay_ms, double loss, double duration_s) {
  // The link's clock is the cycle count (1 kHz: one cycle per millisecond), so a delay is a
  // whole number of cycles exactly.
  net::LinkShimOptions link;
  link.delay_s = delay_ms;
  link.loss = loss;
  link.seed = 12345u;
  net::LinkShim<DeviceState, 512> up(link);
  link.seed = 67890u;
  net::LinkShim<Downlink, 512> down(link);
  LocalModelRenderer renderer(LocalModelRenderOptions{kMaxForce_n, 0.02, 0.1, 0.05});
  DeviceState device{kStart_m, 0.0, 0.0, 0};
  double raw_force_n = 0.0;  // raw mode: the newest force received, held
  std::uint64_t model_sequence = 0;
  const auto steps = static_cast<std::int64_t>(duration_s / kDt_s);
  const std::int64_t tail_from = steps - static_cast<std::int64_t>(1.0 / kDt_s);
  double sum = 0.0;
  double sum_sq = 0.0;
  RunResult result;
  for (std::int64_t k = 0; k < steps; ++k) {
    const double now_s = static_cast<double>(k) * kDt_s;
    // Device side: take what arrived, render from its own fresh state.
    const auto now_cycles = static_cast<double>(k);
    down.deliver(now_cycles, [&](const Downlink& d) {
      if (mode == Mode::kRaw) {
        raw_force_n = d.raw_force_n;
      } else {
        renderer.receive(d.model, now_s);
      }
    });
    double force_n = 0.0;
    if (mode == Mode::kRaw) {
      force_n = std::clamp(raw_force_n, 0.0, kMaxForce_n);
    } else {
      force_n = renderer.render(device.x_m * kIn, device.v_m_per_s * kIn, now_s).dot(-kIn);
    }
    device.rendered_n = force_n;
    if (k >= tail_from) {
      sum += force_n;
      sum_sq += force_n * force_n;
    }
    result.peak_force_n = std::max(result.peak_force_n, force_n);
    up.send(device, now_cycles);
    // The device moves under the hand and the rendered force (semi-implicit Euler).
    const double hand_n = kHandStiffness_n_per_m * (kHandTarget_m - device.x_m) -
                          kHandDamping_n_s_per_m * device.v_m_per_s;
    device.v_m_per_s += (hand_n - force_n) / kDeviceMass_kg * kDt_s;
    device.x_m += device.v_m_per_s * kDt_s;
    ++device.sequence;

    // Simulation side: answer every device state that arrived.
    up.deliver(now_cycles, [&](const DeviceState& s) {
      Downlink d;
      if (mode == Mode::kRaw) {
        const double f_n = quasi_static_force_n(s.x_m);
        d.raw_force_n = f_n > 0.0 ? f_n + kContactDamping_n_s_per_m * s.v_m_per_s : 0.0;
      } else {
        const double y_m = tissue_depth_m(s.rendered_n);
        const double k_n_per_m =
            mode == Mode::kLocalSeries
                ? series_stiffness_n_per_m(kContactStiffness_n_per_m, tissue_stiffness_n_per_m(y_m))
                : kContactStiffness_n_per_m;
        d.model = local_model(s, k_n_per_m, ++model_sequence);
      }
      down.send(d, now_cycles);
    });
  }
  const double n = static_cast<double>(steps - tail_from);
  result.mean_force_n = sum / n;
  result.ripple_rms_n =
      std::sqrt(std::max(0.0, sum_sq / n - result.mean_force_n * result.mean_force_n));
  return result;
}

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

class OneDofLink : public ::testing::TestWithParam<Case> {};

// The hold reached, oscillating or not, is written out so the table in the report comes from
// the test itself.
RunResult run_and_print(const Case& c) {
  const double duration_s = c.delay_ms >= 100 ? 8.0 : 4.0;
  const RunResult r = simulate(c.mode, c.delay_ms, c.loss, duration_s);
  const double f_star = analytic_steady_force_n();
  std::printf(
      "1dof %-16s delay %3d ms loss %2.0f %%: mean %.4f N (error %+.2e %%), ripple %.2e N rms, "
      "peak %.2f N\n",
      name(c.mode), c.delay_ms, c.loss * 100.0, r.mean_force_n,
      (r.mean_force_n - f_star) / f_star * 100.0, r.ripple_rms_n, r.peak_force_n);
  return r;
}

TEST(OneDofAnalysis, AnalyticHoldIsConsistent) {
  const double f = analytic_steady_force_n();
  // Hand spring, contact spring and tissue carry the same force at the hold.
  const double x = position_for_force_m(f);
  EXPECT_NEAR(kHandStiffness_n_per_m * (kHandTarget_m - x), f, 1e-9);
  EXPECT_NEAR(tissue_force_n(tissue_depth_m(f)), f, 1e-9);
  EXPECT_NEAR(quasi_static_force_n(x), f, 1e-9);
  // The tissue is softer than the contact at the hold: the regime where K matters.
  EXPECT_LT(tissue_stiffness_n_per_m(tissue_depth_m(f)), kContactStiffness_n_per_m);
}

TEST_P(OneDofLink, LocalModelWithSeriesStiffnessHoldsTheAnalyticForce) {
  const Case c = GetParam();
  const RunResult r = run_and_print({Mode::kLocalSeries, c.delay_ms, c.loss});
  const double f_star = analytic_steady_force_n();
  EXPECT_NEAR(r.mean_force_n, f_star, 0.01 * f_star);
  EXPECT_LT(r.ripple_rms_n, 0.05);
  EXPECT_LE(r.peak_force_n, kMaxForce_n);
}

// Oscillating: the force swings by more than a tenth of the hold over the last second.
TEST_P(OneDofLink, RawForceIsUnstableFromFiveMilliseconds) {
  const Case c = GetParam();
  const RunResult r = run_and_print({Mode::kRaw, c.delay_ms, c.loss});
  if (c.delay_ms >= 5) {
    EXPECT_GT(r.ripple_rms_n, 0.1 * analytic_steady_force_n());
  }
}

// With the contact stiffness alone the model's error returns through the tissue with gain
// k_c/k_tissue (2.3 at the hold) every round trip. The 20 ms blend low-passes that loop enough
// to hold at 0 ms and at 5 ms without loss (printed, not asserted); from 20 ms it oscillates.
TEST_P(OneDofLink, ContactOnlyModelIsUnstableFromTwentyMilliseconds) {
  const Case c = GetParam();
  const RunResult r = run_and_print({Mode::kLocalContact, c.delay_ms, c.loss});
  if (c.delay_ms >= 20) {
    EXPECT_GT(r.ripple_rms_n, 0.1 * analytic_steady_force_n());
  }
}

TEST(OneDofLink, RawForceHoldsWithoutDelay) {
  const RunResult r = run_and_print({Mode::kRaw, 0, 0.0});
  const double f_star = analytic_steady_force_n();
  EXPECT_NEAR(r.mean_force_n, f_star, 0.01 * f_star);
  EXPECT_LT(r.ripple_rms_n, 0.05);
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
}  // namespace hapsim
