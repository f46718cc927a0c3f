// The FEM knee's force-depth at a thick-tissue landmark (the quadriceps) against the published
// in-vivo range it cites (docs/tissue-materials.md): Zheng & Mak 1999, lower-limb soft tissue,
// initial modulus 0.22-58.4 kPa. A 7 mm fingertip is pressed at 5 mm/s; Hertz's law for a sphere
// on a half-space, F = 4/3 E/(1 - nu^2) sqrt(R) d^1.5 (nu 0.45, the scene's), fitted to the
// force between 2 and 8 mm, gives the effective modulus the hand feels. The solver's own Hertz
// error (+9.3 % at 65,856 tets, docs/fem-validation.md) widens the upper bound. The tangent
// stiffness rises with depth, as in-vivo load-indentation curves do (theirs are quadratic),
// through the scene's strain stiffening.
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

namespace hapsim {
namespace {

// A 7 mm fingertip pressed over the vastus lateralis at 5 mm/s to 8.5 mm past the skin: the
// push along the press against the depth past first touch (m, N).
std::vector<std::pair<double, double>> press_quadriceps(SceneDescription scene) {
  RunSetup setup = make_run_setup(std::move(scene), DeviceChoice::scene_script());
  World& world = *setup.world;
  const Vec3 toward(-0.0449, 0.0094, 0.0925);  // the vastus lateralis, scene frame
  const Vec3 from = Vec3(-0.6, 0.8, 0.0).normalized();
  std::vector<std::pair<double, double>> depth_force;  // m, N
  double s = 0.06;
  double touched = std::nan("");
  while (s > -0.05) {
    DeviceInput in;
    in.p_world = toward + from * s;
    const double push_n = world.step(in, 1e-3).command.force_world_n.dot(from);
    if (std::isnan(touched) && push_n > 0.005) {
      touched = s;
    }
    if (!std::isnan(touched)) {
      depth_force.emplace_back(touched - s, push_n);
      if (touched - s > 0.0085) {
        break;
      }
    }
    s -= (std::isnan(touched) ? 0.05 : 0.005) * 1e-3;
  }
  return depth_force;
}

double force_at(const std::vector<std::pair<double, double>>& depth_force, double d) {
  for (const auto& [dd, f] : depth_force) {
    if (dd >= d) {
      return f;
    }
  }
  return depth_force.back().second;
}

SceneDescription knee_scene() {
  return load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee.json");
}

// The knee with its tissue linear (E1 = 0 in every region): Zheng & Mak's initial modulus alone.
SceneDescription linear_knee_scene() {
  SceneDescription scene = knee_scene();
  auto fem = std::make_shared<FemBodyDescription>(*scene.world.bodies.at(1).fem);
  for (FemRegionMaterial& m : fem->materials) {
    m.material.nonlinear_modulus_pa = 0.0;
  }
  scene.world.bodies.at(1).fem = fem;
  return scene;
}

TEST(FemKneeFeel, TheQuadricepsModulusIsInThePublishedInVivoRange) {
  // The initial modulus: the tissue without its strain stiffening (E1 = 0), as Zheng & Mak's E0.
  SceneDescription scene = linear_knee_scene();
  const double radius_m = scene.world.tools.front().radius_m;
  const double nu = 0.45;
  const std::vector<std::pair<double, double>> depth_force = press_quadriceps(std::move(scene));
  ASSERT_FALSE(depth_force.empty()) << "never touched the skin over the quadriceps";
  // Least squares F = c d^1.5 over 2..8 mm; E = 3 (1 - nu^2) c / (4 sqrt(R)).
  double num = 0.0;
  double den = 0.0;
  for (const auto& [d, f] : depth_force) {
    if (d >= 0.002 && d <= 0.008) {
      num += f * std::pow(d, 1.5);
      den += std::pow(d, 3.0);
    }
  }
  ASSERT_GT(den, 0.0);
  const double e_pa = 3.0 * (1.0 - nu * nu) * (num / den) / (4.0 * std::sqrt(radius_m));
  EXPECT_GE(e_pa, 220.0);
  EXPECT_LE(e_pa, 58.4e3 * 1.093);
  // And a regression band around what it measured when recorded (41.8 kPa, 2026-11-27; 41.0
  // after the knee's surfaces were re-derived without folds, 2026-11-28): the published range
  // alone is 290x wide.
  EXPECT_NEAR(e_pa, 41.8e3, 0.1 * 41.8e3);
  // Linear tissue over bone is close to linear in depth here (Hertz's d^1.5 for a half-space,
  // the bone's nearness against it, the contact patch's nodes): the secant stiffness from 6 to
  // 8 mm within a factor 1.5 of that from 2 to 4 either way (measured 448 -> 346 N/m). The
  // stiffening the hand feels is the E1 law's, asserted in the next test.
  const double k_shallow = (force_at(depth_force, 0.004) - force_at(depth_force, 0.002)) / 0.002;
  const double k_deep = (force_at(depth_force, 0.008) - force_at(depth_force, 0.006)) / 0.002;
  EXPECT_GT(k_deep, k_shallow / 1.5) << "E " << e_pa << " Pa";
  EXPECT_LT(k_deep, k_shallow * 1.5) << "E " << e_pa << " Pa";
  RecordProperty("effective_modulus_pa", std::to_string(e_pa));
  std::printf(
      "quadriceps, E0 only: Hertz-fitted effective modulus %.1f kPa (2-8 mm); tangent %.0f -> "
      "%.0f N/m\n",
      e_pa * 1e-3, k_shallow, k_deep);
}

// With the strain stiffening the scene gives its soft tissue (E1 = 9.4 E0,
// docs/tissue-materials.md) the quadriceps feels as before at the first touch and stiffens with
// depth: the force over the linear tissue's grows with the indentation, as Zheng & Mak's quadratic
// load-indentation does (F = k1 d (1 + (E1/E0) d/h): at 8 mm into ~30 mm of tissue, more than 1.5
// times).
TEST(FemKneeFeel, TheQuadricepsStiffensWithDepthAsTheInVivoCurvesDo) {
  const auto linear = press_quadriceps(linear_knee_scene());
  const auto stiffening = press_quadriceps(knee_scene());
  ASSERT_FALSE(linear.empty());
  ASSERT_FALSE(stiffening.empty());
  const double shallow = force_at(stiffening, 0.0005) / force_at(linear, 0.0005);
  const double deep = force_at(stiffening, 0.008) / force_at(linear, 0.008);
  EXPECT_LT(shallow, 1.2);
  EXPECT_GT(deep, 1.5);
  EXPECT_GT(deep, shallow + 0.3);
  std::printf("quadriceps, stiffening over linear: x%.2f at 0.5 mm, x%.2f at 8 mm (%.2f N)\n",
              shallow, deep, force_at(stiffening, 0.008));
}

}  // namespace
}  // namespace hapsim
