// The passivity observer/controller against analytic one-ports: a passive spring is left alone
// and its stored energy observed; a negative damper, a delayed spring and a saturated damper
// generate energy at rates known in closed form, which the controller takes out (or, saturated,
// takes out at its bound); non-finite input gives zero force.
#include "hapsim/device/passivity_observer.h"

#include "hapsim/core/error.h"

#include "support/allocation_counter.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

constexpr double kDt_s = 0.001;
constexpr double kPi = std::numbers::pi;

// Motion along x: x(t) = A·sin(ωt), v(t) = A·ω·cos(ωt).
struct Sine {
  double amplitude_m;
  double omega_rad_per_s;
  [[nodiscard]] double x(double t_s) const { return amplitude_m * std::sin(omega_rad_per_s * t_s); }
  [[nodiscard]] double v(double t_s) const {
    return amplitude_m * omega_rad_per_s * std::cos(omega_rad_per_s * t_s);
  }
};

TEST(PassivityObserver, LeavesAPassiveSpringAloneAndObservesItsStoredEnergy) {
  // A one-sided contact spring (push-only, 1000 N/m) pressed 5 mm and released at 2 Hz.
  constexpr double kStiffness_n_per_m = 1000.0;
  const Sine path{0.005, 2.0 * kPi * 2.0};
  PassivityObserver observer;
  // The sampled estimate dips below zero by at most ½·K·(v·dt)² as the spring unloads.
  const double v_max = path.amplitude_m * path.omega_rad_per_s;
  const double dip_j = 0.5 * kStiffness_n_per_m * (v_max * kDt_s) * (v_max * kDt_s);
  ASSERT_LT(dip_j, observer.options().energy_tolerance_j);
  double lowest_j = 0.0;
  for (int k = 0; k <= 250; ++k) {  // 0.25 s: half a period, in and out
    const double t_s = k * kDt_s;
    const double x_m = path.x(t_s);
    const Vec3 f(x_m > 0.0 ? -kStiffness_n_per_m * x_m : 0.0, 0.0, 0.0);
    const Vec3 out = observer.filter(f, Vec3(path.v(t_s), 0.0, 0.0), kDt_s);
    ASSERT_EQ(out, f) << "at " << t_s << " s";
    lowest_j = std::min(lowest_j, observer.observed_energy_j());
    if (k == 125) {
      // At the deepest point the spring holds ½·K·A² (the sum is a Riemann sum of it).
      EXPECT_NEAR(observer.observed_energy_j(),
                  0.5 * kStiffness_n_per_m * path.amplitude_m * path.amplitude_m,
                  1e-3 * 0.5 * kStiffness_n_per_m * path.amplitude_m * path.amplitude_m);
    }
  }
  // Released: everything stored came back, to the sampling error.
  EXPECT_NEAR(observer.observed_energy_j(), 0.0, dip_j);
  EXPECT_GE(lowest_j, -dip_j);
  EXPECT_EQ(observer.counts().acted, 0u);
  EXPECT_EQ(observer.counts().dissipated_j, 0.0);
  EXPECT_EQ(observer.counts().cycles, 251u);
}

TEST(PassivityObserver, TakesOutWhatANegativeDamperGenerates) {
  // f = +b·v pushes along the motion: it gives out b·v² every second.
  constexpr double kNegativeDamping_n_s_per_m = 5.0;
  const Sine path{0.01, 2.0 * kPi * 3.0};
  PassivityObserver observer;
  PassivityObserver watcher({.enabled = false});
  const double tolerance_j = observer.options().energy_tolerance_j;
  double generated_j = 0.0;  // Σ b·v²·dt, summed here
  double output_j = 0.0;     // energy the environment absorbed with the filtered force
  for (int k = 0; k < 1000; ++k) {
    const Vec3 v(path.v(k * kDt_s), 0.0, 0.0);
    const Vec3 f = kNegativeDamping_n_s_per_m * v;
    generated_j += kNegativeDamping_n_s_per_m * v.squaredNorm() * kDt_s;
    const Vec3 out = observer.filter(f, v, kDt_s);
    ASSERT_EQ(watcher.filter(f, v, kDt_s), f);  // disabled: observes only
    output_j -= out.dot(v) * kDt_s;
    ASSERT_GE(output_j, -tolerance_j - 1e-15) << "at cycle " << k;
    ASSERT_NEAR(observer.observed_energy_j(), output_j, 1e-12);
  }
  // The watcher saw the whole generation: b·V²·T/2 over whole periods (V = A·ω).
  const double speed_m_per_s = path.amplitude_m * path.omega_rad_per_s;
  EXPECT_NEAR(-watcher.observed_energy_j(),
              kNegativeDamping_n_s_per_m * speed_m_per_s * speed_m_per_s * 1.0 / 2.0, 1e-9);
  EXPECT_NEAR(watcher.observed_energy_j(), -generated_j, 1e-12);
  // Books balance: generated = dissipated + what is still owed (≤ tolerance).
  EXPECT_NEAR(observer.counts().dissipated_j, generated_j + observer.observed_energy_j(), 1e-12);
  // It acts on most cycles; near the turning points b·v²·dt is below the tolerance and the
  // deficit builds up over a few cycles first.
  EXPECT_GT(observer.counts().acted, 800u);
  EXPECT_EQ(watcher.counts().acted, 0u);
}

TEST(PassivityObserver, CatchesADelayedSpring) {
  // A spring that answers 20 ms late, f(t) = −K·x(t − τ): along x = A·sin(ωt) it gives out
  // π·K·A²·sin(ωτ) a period (the raw-force-over-a-network failure in one line).
  constexpr double kStiffness_n_per_m = 500.0;
  constexpr int kDelayCycles = 20;
  const Sine path{0.004, 2.0 * kPi * 4.0};
  // Unbounded in effect (Hannaford & Ryu's controller): the needed α = |f|/|v| peaks near the
  // turning points, which a device's damping rating would cap.
  PassivityObserver observer({.max_damping_n_s_per_m = 1e4});
  PassivityObserver watcher({.enabled = false});
  double output_j = 0.0;
  double lowest_j = 0.0;
  for (int k = 0; k < 2000; ++k) {  // 8 periods
    const double t_s = k * kDt_s;
    const Vec3 v(path.v(t_s), 0.0, 0.0);
    const Vec3 f(-kStiffness_n_per_m * path.x(t_s - kDelayCycles * kDt_s), 0.0, 0.0);
    const Vec3 out = observer.filter(f, v, kDt_s);
    (void)watcher.filter(f, v, kDt_s);
    output_j -= out.dot(v) * kDt_s;
    lowest_j = std::min(lowest_j, output_j);
  }
  const double per_period_j = kPi * kStiffness_n_per_m * path.amplitude_m * path.amplitude_m *
                              std::sin(path.omega_rad_per_s * kDelayCycles * kDt_s);
  // The sum starts with the spring already loaded (x(−τ) ≠ 0): compare over whole periods with a
  // percent's room for the sampling.
  EXPECT_NEAR(-watcher.observed_energy_j(), 8.0 * per_period_j, 0.01 * 8.0 * per_period_j);
  EXPECT_GE(lowest_j, -observer.options().energy_tolerance_j - 1e-15);
  EXPECT_EQ(observer.counts().saturated, 0u);
  EXPECT_GT(observer.counts().dissipated_j, 0.9 * 8.0 * per_period_j);
}

TEST(PassivityObserver, SaturatedDamperTakesOutOnlyItsBound) {
  // A −100 N·s/m damper at a steady 0.1 m/s against a 20 N·s/m bound: each cycle the controller
  // takes out 20·v²·dt of the 100·v²·dt generated, so the deficit grows by 80·v²·dt a cycle.
  PassivityObserver observer({.max_damping_n_s_per_m = 20.0});
  const Vec3 v(0.1, 0.0, 0.0);
  const Vec3 f = 100.0 * v;
  for (int k = 0; k < 100; ++k) {
    const Vec3 out = observer.filter(f, v, kDt_s);
    ASSERT_NEAR(out.x(), (100.0 - 20.0) * 0.1, 1e-12);
  }
  EXPECT_NEAR(observer.observed_energy_j(), -100 * 80.0 * 0.01 * kDt_s, 1e-12);
  EXPECT_EQ(observer.counts().saturated, 100u);
  EXPECT_NEAR(observer.counts().dissipated_j, 100 * 20.0 * 0.01 * kDt_s, 1e-12);
}

TEST(PassivityObserver, WorksOnVectorsAlongTheVelocityOnly) {
  PassivityObserver observer;
  // Sliding along a wall: the normal force does no work, whatever its size.
  const Vec3 slide(0.05, 0.02, 0.0);
  const Vec3 normal_force(0.0, 0.0, 8.0);
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(observer.filter(normal_force, slide, kDt_s), normal_force);
  }
  EXPECT_EQ(observer.observed_energy_j(), 0.0);
  // A tangential push along the slide is active: the correction is a damper along v, and the
  // normal force is kept.
  const Vec3 push = normal_force + 4.0 * slide;
  for (int k = 0; k < 100; ++k) {
    const Vec3 out = observer.filter(push, slide, kDt_s);
    const Vec3 correction = out - push;
    ASSERT_NEAR(correction.cross(slide).norm(), 0.0, 1e-12);
    ASSERT_LE(correction.dot(slide), 0.0);
    ASSERT_GE(observer.observed_energy_j(), -observer.options().energy_tolerance_j);
  }
  EXPECT_GT(observer.counts().acted, 0u);
}

TEST(PassivityObserver, NonFiniteInputGivesZeroForce) {
  PassivityObserver observer;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  (void)observer.filter(Vec3(-1.0, 0.0, 0.0), Vec3(0.1, 0.0, 0.0), kDt_s);  // absorbs 0.1 mJ
  const double before_j = observer.observed_energy_j();
  EXPECT_EQ(observer.filter(Vec3(nan, 0.0, 0.0), Vec3(0.1, 0.0, 0.0), kDt_s), Vec3::Zero());
  EXPECT_EQ(observer.filter(Vec3(1.0, 0.0, 0.0), Vec3(0.0, kInf, 0.0), kDt_s), Vec3::Zero());
  EXPECT_EQ(observer.filter(Vec3(1.0, 0.0, 0.0), Vec3(0.1, 0.0, 0.0), nan), Vec3::Zero());
  EXPECT_EQ(observer.filter(Vec3(1.0, 0.0, 0.0), Vec3(0.1, 0.0, 0.0), 0.0), Vec3::Zero());
  // Finite but absurd: f·v overflows.
  EXPECT_EQ(observer.filter(Vec3(1e300, 0.0, 0.0), Vec3(1e300, 0.0, 0.0), kDt_s), Vec3::Zero());
  EXPECT_EQ(observer.counts().nonfinite, 5u);
  EXPECT_EQ(observer.observed_energy_j(), before_j);
}

TEST(PassivityObserver, ResetForgetsTheEnergyAndKeepsTheCounts) {
  PassivityObserver observer;
  for (int k = 0; k < 10; ++k) {
    (void)observer.filter(Vec3(1.0, 0.0, 0.0), Vec3(0.1, 0.0, 0.0), kDt_s);
  }
  ASSERT_GT(observer.counts().acted, 0u);
  const auto counts = observer.counts();
  observer.reset();
  EXPECT_EQ(observer.observed_energy_j(), 0.0);
  EXPECT_EQ(observer.counts().acted, counts.acted);
  EXPECT_EQ(observer.counts().cycles, counts.cycles);
}

TEST(PassivityObserver, RefusesBadOptions) {
  EXPECT_THROW(PassivityObserver({.max_damping_n_s_per_m = -1.0}), Error);
  EXPECT_THROW(PassivityObserver({.max_damping_n_s_per_m = kInf}), Error);
  EXPECT_THROW(PassivityObserver({.energy_tolerance_j = std::numeric_limits<double>::quiet_NaN()}),
               Error);
}

TEST(PassivityObserver, AllocatesNothing) {
  PassivityObserver observer;
  const long before = test::allocation_count();
  Vec3 sum = Vec3::Zero();
  for (int k = 0; k < 1000; ++k) {
    sum += observer.filter(Vec3(0.01 * k, 0.0, 1.0), Vec3(0.1, -0.05, 0.0), kDt_s);
  }
  EXPECT_EQ(test::allocation_count() - before, 0);
  EXPECT_TRUE(sum.allFinite());
}

}  // namespace
}  // namespace hapsim
