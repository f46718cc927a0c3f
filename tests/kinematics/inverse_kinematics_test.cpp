// Inverse kinematics: FK(IK(p)) = p within 0.1 mm / 0.1° for reachable poses (made by FK of
// joint vectors inside the limits), a clear "not reached" for poses out of reach, joint limits
// never exceeded, tracking converges in a few iterations, and nothing is allocated.
#include "hapsim/kinematics/inverse_kinematics.h"
#include "hapsim/kinematics/dh_chain.h"
#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/kinematics/urdf_chain.h"

#include "support/allocation_counter.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <numbers>
#include <random>
#include <vector>

namespace hapsim {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
constexpr double kTolM = 1e-4;                 // 0.1 mm
constexpr double kTolRad = 0.1 * kPi / 180.0;  // 0.1°

// The procedural slave: 6 axes, spherical wrist, the GP7's lengths and limits.
SerialChain six_axis() {
  return make_procedural_motoman();
}

std::vector<double> random_q(const SerialChain& chain, std::mt19937& rng, double margin = 0.05) {
  std::vector<double> q;
  for (const ChainJoint& j : chain.joints()) {
    const double lo = std::max(j.lower, -kPi), hi = std::min(j.upper, kPi);
    std::uniform_real_distribution<double> u(lo + margin * (hi - lo), hi - margin * (hi - lo));
    q.push_back(u(rng));
  }
  return q;
}

void expect_round_trips(const SerialChain& chain, int poses, bool cold_start) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.05);
  int reached = 0;
  for (int k = 0; k < poses; ++k) {
    const std::vector<double> q_true = random_q(chain, rng);
    const Iso3 target = chain.forward(q_true);
    std::vector<double> seed(q_true.size(), 0.0);
    if (!cold_start) {
      for (std::size_t i = 0; i < seed.size(); ++i) {
        seed[i] = q_true[i] + noise(rng);  // tracking: last cycle's answer is close
      }
    }
    std::vector<double> q(q_true.size());
    const IkResult r = solve_ik(chain, target, seed, q);
    double pos = 0.0, rot = 0.0;
    pose_error(chain.forward(q), target, &pos, &rot);
    EXPECT_TRUE(chain.within_limits(q)) << k;
    if (r.reached) {
      ++reached;
      EXPECT_LE(pos, kTolM) << k;
      EXPECT_LE(rot, kTolRad) << k;
      EXPECT_NEAR(pos, r.position_error_m, 1e-12);
    } else {
      ADD_FAILURE() << "pose " << k << " not reached: " << r.position_error_m << " m, "
                    << r.rotation_error_rad << " rad after " << r.starts << " starts";
    }
    if (!cold_start) {
      EXPECT_EQ(r.starts, 1) << k;  // tracking converges from the seed
      EXPECT_LE(r.iterations, 10) << k;
    }
  }
  EXPECT_EQ(reached, poses);
}

TEST(InverseKinematics, RoundTripsWhenTrackingAndFromCold) {
  const SerialChain arm = six_axis();
  expect_round_trips(arm, 200, false);
  expect_round_trips(arm, 100, true);
}

TEST(InverseKinematics, Gp7RoundTrips) {
  const fs::path urdf = test::data_path("motoman_gp7/gp7.urdf");
  HAPSIM_SKIP_WITHOUT_DATA(fs::exists(urdf), "Motoman GP7 URDF not found at " << urdf);
  UrdfChainOptions o;
  o.load_collision_meshes = false;
  const SerialChain gp7 = load_urdf_chain(urdf, o);
  expect_round_trips(gp7, 200, false);
  expect_round_trips(gp7, 100, true);
}

TEST(InverseKinematics, OutOfReachIsReportedAndStaysInLimits) {
  const SerialChain arm = six_axis();
  std::vector<double> q(6), seed(6, 0.0);
  for (const Vec3& p : {Vec3(3.0, 0.0, 0.5), Vec3(0.0, 0.0, 2.5), Vec3(-1.2, 0.9, 0.3)}) {
    Iso3 target = Iso3::Identity();
    target.translation() = p;
    const IkResult r = solve_ik(arm, target, seed, q);
    EXPECT_FALSE(r.reached) << p.transpose();
    EXPECT_GT(r.position_error_m, 0.1) << p.transpose();
    EXPECT_TRUE(arm.within_limits(q));
    // The best effort points the arm at the target: nearer than the home pose is.
    EXPECT_LT((arm.forward(q).translation() - p).norm(),
              (arm.forward(seed).translation() - p).norm());
  }
  // A NaN target is not reached and gives the (clamped) seed back.
  Iso3 bad = Iso3::Identity();
  bad.translation().x() = std::nan("");
  const IkResult r = solve_ik(arm, bad, seed, q);
  EXPECT_FALSE(r.reached);
  EXPECT_EQ(q, seed);
}

TEST(InverseKinematics, PositionOnlyForAShortChain) {
  const std::vector<DhRow> rows{{.a_m = 0.3}, {.a_m = 0.2}};
  const SerialChain planar = make_dh_chain(rows);
  IkOptions o;
  o.orientation = false;
  std::array<double, 2> q{}, seed{0.1, 0.1};
  Iso3 target = Iso3::Identity();
  target.translation() = Vec3(0.25, 0.3, 0.0);
  const IkResult r = solve_ik(planar, target, seed, q, o);
  EXPECT_TRUE(r.reached);
  EXPECT_NEAR((planar.forward(q).translation() - target.translation()).norm(), 0.0, kTolM);
}

TEST(InverseKinematics, NoAllocation) {
  const SerialChain arm = six_axis();
  std::mt19937 rng(3);
  std::vector<Iso3> targets;
  for (int k = 0; k < 20; ++k) {
    targets.push_back(arm.forward(random_q(arm, rng)));
  }
  targets.push_back(Iso3(Eigen::Translation3d(5.0, 0.0, 0.0)));  // unreachable: all restarts
  std::vector<double> q(6), seed(6, 0.0);
  const long before = test::allocation_count();
  for (const Iso3& t : targets) {
    (void)solve_ik(arm, t, seed, q);
    (void)arm.jacobian(q);
  }
  EXPECT_EQ(test::allocation_count() - before, 0);
  auto* probe = new int(1);  // the counter itself works
  EXPECT_GT(test::allocation_count(), before);
  delete probe;
}

}  // namespace
}  // namespace hapsim
