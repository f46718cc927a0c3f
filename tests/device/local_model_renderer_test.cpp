#include "hapsim/device/local_model_renderer.h"

#include "hapsim/core/error.h"

#include "support/allocation_counter.h"

#include <algorithm>
#include <limits>

#include <gtest/gtest.h>

namespace hapsim {
namespace {

// A wall along +z at z = 0 pressed to 1 mm: f0 = 1 N up, K = 1000 N/m along z.
LocalContactModel wall_model(std::uint64_t sequence = 1) {
  LocalContactModel m;
  m.x0_world_m = Vec3(0.0, 0.0, -0.001);
  m.f0_world_n = Vec3(0.0, 0.0, 1.0);
  m.stiffness_n_per_m = Vec3(0.0, 0.0, 1000.0).asDiagonal();
  m.damping_n_s_per_m = Vec3(0.0, 0.0, 2.0).asDiagonal();
  m.normal_world = Vec3::UnitZ();
  m.validity_radius_m = 0.01;
  m.sequence = sequence;
  m.valid = true;
  return m;
}

LocalModelRenderOptions no_blend() {
  return {10.0, 0.0, 0.1, 0.05};
}

TEST(LocalContactModel, SeriesStiffness) {
  EXPECT_DOUBLE_EQ(series_stiffness_n_per_m(2000.0, 2000.0), 1000.0);
  EXPECT_DOUBLE_EQ(series_stiffness_n_per_m(2000.0, kInf), 2000.0);  // rigid body
  EXPECT_EQ(series_stiffness_n_per_m(2000.0, -1.0), 0.0);
  EXPECT_EQ(series_stiffness_n_per_m(std::numeric_limits<double>::quiet_NaN(), 1.0), 0.0);
}

// A profile along the normal: linear between its points, the end slopes beyond, in place of
// f0 + K·(x − x0) along the normal only; across it and for damping the linear model stays.
TEST(LocalContactModel, AProfileReplacesTheLinearSpringAlongTheNormal) {
  LocalContactModel m = wall_model();  // normal +z, x0 at z = −1 mm, f0 1 N, K 1000, B 2
  m.stiffness_n_per_m(0, 0) = 500.0;   // across the normal too
  m.profile_count = 3;
  m.profile_depth_m = {-0.001, 0.0, 0.002};
  m.profile_push_n = {0.0, 1.0, 5.0};  // 1000 N/m, then 2000 N/m deeper
  EXPECT_DOUBLE_EQ(profile_push_n(m, 0.001), 3.0);
  EXPECT_DOUBLE_EQ(profile_push_n(m, 0.004), 9.0);    // the last slope beyond the end
  EXPECT_DOUBLE_EQ(profile_push_n(m, -0.002), -1.0);  // the first slope before the start
  // 3 mm deeper than x0 and 1 mm across, moving in at 0.1 m/s.
  const Vec3 x = m.x0_world_m + Vec3(0.001, 0.0, -0.003);
  const Vec3 f = local_model_force(m, x, Vec3(0.0, 0.0, -0.1));
  EXPECT_NEAR(f.z(), 7.0 + 2.0 * 0.1, 1e-12);  // the profile at 3 mm, plus damping
  EXPECT_NEAR(f.x(), -0.5, 1e-12);             // K across the normal, as without a profile
  m.profile_count = 0;
  EXPECT_NEAR(local_model_force(m, x, Vec3(0.0, 0.0, -0.1)).z(), 4.0 + 0.2, 1e-12);
  EXPECT_TRUE(std::isnan(profile_push_n(m, 0.001)));
}

TEST(LocalContactModel, TissueCoupledForceIsTheQuasiStaticForceForSeriesStiffness) {
  // Linear tissue k_t = 500 under a contact k_c = 2000: series 400 N/m. At x0 = 10 mm with the
  // tissue settled under a rendered 3 N (y = 6 mm, compression 4 mm), the quasi-static force at
  // x0 is 400 · 0.01 = 4 N whatever was rendered.
  const double k_s = series_stiffness_n_per_m(2000.0, 500.0);
  const double y_m = 3.0 / 500.0;
  EXPECT_NEAR(tissue_coupled_force_n(3.0, 0.01 - y_m, 2000.0, k_s), 4.0, 1e-12);
  // With the contact stiffness alone it is the contact spring's own force, k_c · compression.
  EXPECT_NEAR(tissue_coupled_force_n(3.0, 0.01 - y_m, 2000.0, 2000.0), 2000.0 * (0.01 - y_m),
              1e-12);
}

TEST(LocalModelRenderer, RendersTheLinearModelAtTheDevicesOwnPosition) {
  LocalModelRenderer r(no_blend());
  r.receive(wall_model(), 0.0);
  // 1 mm deeper than x0: 1 N + 1000 N/m · 1 mm = 2 N up; moving down at 0.1 m/s adds 0.2 N.
  const Vec3 f = r.render(Vec3(0.0, 0.0, -0.002), Vec3(0.0, 0.0, -0.1), 0.001);
  EXPECT_NEAR(f.z(), 2.2, 1e-12);
  EXPECT_NEAR(f.x(), 0.0, 1e-12);
}

TEST(LocalModelRenderer, PushOnlyRadiusAndClamp) {
  LocalModelRenderer r(no_blend());
  r.receive(wall_model(), 0.0);
  EXPECT_EQ(r.render(Vec3(0.0, 0.0, 0.001), Vec3::Zero(), 0.0), Vec3::Zero());    // would pull
  EXPECT_EQ(r.render(Vec3(0.0, 0.02, -0.001), Vec3::Zero(), 0.0), Vec3::Zero());  // outside
  const Vec3 f = r.render(Vec3(0.0, 0.0, -0.009), Vec3::Zero(), 0.0);             // 9 N
  EXPECT_NEAR(f.z(), 9.0, 1e-9);
  LocalModelRenderer tight({5.0, 0.0, 0.1, 0.05});
  tight.receive(wall_model(), 0.0);
  EXPECT_NEAR(tight.render(Vec3(0.0, 0.0, -0.009), Vec3::Zero(), 0.0).norm(), 5.0, 1e-12);
  EXPECT_EQ(r.counts().pull_zeroed, 1u);
  EXPECT_EQ(r.counts().outside_radius, 1u);
  EXPECT_EQ(tight.counts().clamped, 1u);
}

TEST(LocalModelRenderer, HoldsThePushAlongTheNormalToTheModelsCap) {
  LocalModelRenderer r(no_blend());
  LocalContactModel m = wall_model(1);
  m.max_normal_force_n = 1.5;
  r.receive(m, 0.0);
  const Vec3 x0 = m.x0_world_m;
  // 1 mm deeper: the linear model says f0 + K·1 mm; the contact saturates at 1.5 N.
  const Vec3 deeper = x0 - Vec3(0.0, 0.0, 0.001);
  const double linear_n = local_model_force(m, deeper, Vec3::Zero()).z();
  EXPECT_GT(linear_n, 1.5);
  EXPECT_NEAR(r.render(deeper, Vec3::Zero(), 0.0).z(), 1.5, 1e-12);
  EXPECT_EQ(r.counts().capped, 1u);
  // Shallower than the cap: the model as it is.
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 0.0).z(), m.f0_world_n.z(), 1e-12);
}

TEST(LocalModelRenderer, FadesToZeroWhenTheNewestModelGoesStale) {
  LocalModelRenderer r(no_blend());  // stale after 100 ms, faded out 50 ms later
  r.receive(wall_model(), 1.0);
  const Vec3 x0(0.0, 0.0, -0.001);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 1.1).z(), 1.0, 1e-12);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 1.125).z(), 0.5, 1e-9);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 1.15).z(), 0.0, 1e-9);
  EXPECT_EQ(r.render(x0, Vec3::Zero(), 1.151).z(), 0.0);
  EXPECT_EQ(r.render(x0, Vec3::Zero(), 5.0).z(), 0.0);
  // A fresh model brings the force back, ramped in over the re-engagement (0.5 s).
  r.receive(wall_model(2), 5.0);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 5.0).z(), 0.0, 1e-12);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 5.05).z(), 0.1, 1e-12);
  EXPECT_EQ(r.counts().reengaged, 1u);
}

TEST(LocalModelRenderer, AfterAnOutageTheContactComesBackAsARampNotAJolt) {
  // The device went 4 mm deeper while the force was off: the model there says 5 N. It grows
  // linearly over the 0.5 s re-engagement, though a model arrives every millisecond (each takes
  // the ramp over instead of restarting the 20 ms blend), and is whole at its end.
  LocalModelRenderer r({10.0, 0.02, 0.1, 0.05, 0.5});
  r.receive(wall_model(1), 0.0);
  const Vec3 held(0.0, 0.0, -0.001);
  EXPECT_NEAR(r.render(held, Vec3::Zero(), 0.05).z(), 1.0, 1e-12);
  EXPECT_EQ(r.render(held, Vec3::Zero(), 0.3).z(), 0.0);  // stale since 0.1 s, faded by 0.15 s
  const Vec3 deep(0.0, 0.0, -0.005);
  EXPECT_EQ(r.render(deep, Vec3::Zero(), 0.4).z(), 0.0);
  std::uint64_t sequence = 2;
  for (int k = 0; k <= 600; ++k) {
    const double t_s = 0.4 + 1e-3 * k;
    LocalContactModel m = wall_model(sequence++);
    m.x0_world_m = deep;
    m.f0_world_n.z() = 5.0;
    r.receive(m, t_s);
    const double f_n = r.render(deep, Vec3::Zero(), t_s).z();
    const double expected_n = 5.0 * std::min(1.0, (t_s - 0.4) / 0.5);
    ASSERT_NEAR(f_n, expected_n, 1e-9) << "at " << t_s << " s";
  }
  EXPECT_EQ(r.counts().reengaged, 1u);
  // A steady stream afterwards blends at the ordinary 20 ms again.
  LocalContactModel harder = wall_model(sequence++);
  harder.x0_world_m = deep;
  harder.f0_world_n.z() = 6.0;
  r.receive(harder, 1.05);
  EXPECT_NEAR(r.render(deep, Vec3::Zero(), 1.07).z(), 6.0, 1e-12);
}

TEST(LocalModelRenderer, BlendsANewModelInOverTheBlendTime) {
  LocalModelRenderer r({10.0, 0.02, 0.1, 0.05});
  r.receive(wall_model(1), 0.0);
  const Vec3 x0(0.0, 0.0, -0.001);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 0.0).z(), 0.0, 1e-12);  // from nothing
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 0.02).z(), 1.0, 1e-12);
  LocalContactModel harder = wall_model(2);
  harder.f0_world_n.z() = 3.0;
  r.receive(harder, 0.05);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 0.05).z(), 1.0, 1e-12);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 0.06).z(), 2.0, 1e-12);
  EXPECT_NEAR(r.render(x0, Vec3::Zero(), 0.07).z(), 3.0, 1e-12);
}

// A served rig's pad leaving the knee (2026-11-29): the master steps out quickly, the contact's
// damping would pull for that cycle (zeroed, as a pull is never felt), and the simulation's
// models alternate between the contact and a step with no touch (valid, no normal). The blend
// started from the old model's bare force, a pull, and the free-space model rendered it with no
// push-only rule: the pulls stacked up to 11 N into the tissue. The blend starts from what was
// felt, so the force stays a push no larger than the contact's.
TEST(LocalModelRenderer, AStreamAlternatingWithFreeSpaceNeverStacksAPull) {
  LocalModelRenderer r({10.0, 0.02, 0.1, 0.05});
  LocalContactModel touch_free;
  touch_free.valid = true;  // the simulation's tool is usable, it touches nothing this step
  touch_free.validity_radius_m = 0.01;
  Vec3 x_m(0.0, 0.0, -0.001);
  double largest_push_n = 0.0;
  for (int k = 0; k < 200; ++k) {  // 1 ms cycles
    const double t_s = 1e-3 * k;
    LocalContactModel contact = wall_model(static_cast<std::uint64_t>(k) + 1);
    contact.x0_world_m = x_m;
    contact.f0_world_n.z() = 1.5;
    contact.damping_n_s_per_m = Vec3(0.0, 0.0, 16.0).asDiagonal();
    r.receive(k % 4 == 1 ? touch_free : contact, t_s);
    // Every fourth cycle the device steps 0.16 mm out of the tissue: 0.16 m/s for one cycle.
    const Vec3 v_m_per_s = k % 4 == 0 ? Vec3(0.0, 0.0, 0.16) : Vec3::Zero();
    const Vec3 f_n = r.render(x_m, v_m_per_s, t_s);
    ASSERT_GE(f_n.z(), -1e-12) << "a pull into the tissue at cycle " << k;
    largest_push_n = std::max(largest_push_n, f_n.norm());
  }
  EXPECT_LE(largest_push_n, 1.5 + 1e-9);  // never more than the contact's own push
  EXPECT_GT(r.counts().pull_zeroed, 0u);  // the damping did pull on the steps out
}

TEST(LocalModelRenderer, ReceivingAndRenderingAllocateNothing) {
  LocalModelRenderer r;
  const long before = test::allocation_count();
  Vec3 sum = Vec3::Zero();
  for (int k = 0; k < 1000; ++k) {  // haptic path
    const double t_s = 1e-3 * k;
    r.receive(wall_model(static_cast<std::uint64_t>(k) + 1), t_s);
    sum += r.render(Vec3(0.0, 0.0, -0.002), Vec3::Zero(), t_s);
  }
  EXPECT_EQ(test::allocation_count() - before, 0);
  EXPECT_TRUE(sum.allFinite());
}

TEST(LocalModelRenderer, RefusesBrokenModelsAndNeverReturnsNaN) {
  LocalModelRenderer r(no_blend());
  r.receive(wall_model(), 0.0);
  LocalContactModel broken = wall_model(2);
  broken.f0_world_n.x() = std::numeric_limits<double>::quiet_NaN();
  r.receive(broken, 0.001);
  LocalContactModel negative = wall_model(3);
  negative.stiffness_n_per_m(2, 2) = -5.0;
  r.receive(negative, 0.001);
  EXPECT_EQ(r.counts().models_refused, 2u);
  EXPECT_EQ(r.newest().sequence, 1u);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(r.render(Vec3(nan, 0.0, 0.0), Vec3::Zero(), 0.002), Vec3::Zero());
  EXPECT_TRUE(r.render(Vec3(0.0, 0.0, -0.002), Vec3::Zero(), 0.002).allFinite());
  EXPECT_THROW(LocalModelRenderer({0.0, 0.0, 0.1, 0.05}), Error);
  EXPECT_THROW(LocalModelRenderer({1.0, -1.0, 0.1, 0.05}), Error);
}

}  // namespace
}  // namespace hapsim
