// A rig served (issue 33, item 3): `hapsim serve scenes/telepalpation.json --wait-for-device` +
// `hapsim device` (the simulated master playing the scene's tele-palpation) on loopback, against
// the same run in one process. The master's joints drive the served slave, whose pad palpates the
// FEM knee; serve sends the pad's local contact models; the device host renders them where the
// slave's target puts the pad and feels them through the master's Jᵀ, and tells serve the force
// its torques stand for, which the tissue takes as its load (SPEC §8).
//  * The served world and what the device host rendered reproduce the one-process run within the
//    knee's three-process tolerances: the pad's peak force and the master's peak joint torque
//    within 5 % (measured within 0.05 % on an idle machine), its contacts within 5 % of the
//    one-process count (allowing for serve's pace).
//  * Those 5 % hold while serve's FEM keeps up. Beside stress-ng its updates come at half their
//    rate or less, and the pad sliding between the landmarks meets models 30 ms old: the served
//    tissue is then not the one-process run's (+28 % in 1 of 3 such runs), as for a served FEM
//    block (fem_serve_process_test.cpp), and the bounds are that test's.
//  * A headless viewer (hapsim watch) sees the pad's force, not the master's zero tip force.
//  * The pick-and-place rig served sets the ball down where one process does (below).
#include "hapsim/core/types.h"

#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

using namespace std::chrono_literals;
using hapsim::test::BackgroundHapsim;

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/telepalpation.json";
const std::string kPickAndPlace = std::string(HAPSIM_SOURCE_DIR) + "/scenes/teleop.json";

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(RigServe, ServeAndMasterReproduceTheOneProcessTelepalpation) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto one_json = hapsim::test::temp_path("rig_one.json");
  const auto served_json = hapsim::test::temp_path("rig_served.json");
  const auto device_json = hapsim::test::temp_path("rig_device.json");
  const hapsim::test::RunResult one = hapsim::test::run_hapsim(
      "run " + kScene + " --duration 10.5 --quiet --json " + one_json.string());
  ASSERT_EQ(one.exit_code, 0) << one.output;

  const std::string net = " --session rig-serve --domain 81";
  BackgroundHapsim serve(
      "serve " + kScene + " --wait-for-device --duration 10.5 --json " + served_json.string() + net,
      hapsim::test::temp_path("rig_serve.log"));
  ASSERT_TRUE(serve.wait_for("waiting", 60s)) << serve.output();
  // A headless viewer: it draws the served master and slave from the view states' rig part.
  const auto watch_json = hapsim::test::temp_path("rig_watch.json");
  const auto watch_png = hapsim::test::temp_path("rig_watch.png");
  BackgroundHapsim watch("watch --duration 11.5 --json " + watch_json.string() + " --snapshot " +
                             watch_png.string() + net,
                         hapsim::test::temp_path("rig_watch.log"));
  BackgroundHapsim device("device --duration 11" + net + " --json " + device_json.string(),
                          hapsim::test::temp_path("rig_device.log"));
  EXPECT_EQ(serve.wait(), 0) << serve.output();
  EXPECT_EQ(device.wait(), 0) << device.output();
  EXPECT_EQ(watch.wait(), 0) << watch.output();
  std::printf("%s\n%s\n", serve.output().c_str(), device.output().c_str());
  EXPECT_NE(device.output().find("master arm   of the served rig"), std::string::npos);
  if (const std::string why = test::serve_too_slow_for_real_time(serve.output()); !why.empty()) {
    GTEST_SKIP() << why;
  }

  const nlohmann::json a = read_json(one_json);
  const nlohmann::json b = read_json(served_json);
  const nlohmann::json d = read_json(device_json);
  const double one_peak_n = a["peak_tool_force_n"].get<double>();
  const double one_torque_nm = a["peak_master_torque_nm"].get<double>();
  EXPECT_GT(one_peak_n, 3.0);  // the pad pressed the knee
  EXPECT_GT(one_torque_nm, 0.5);
  // Serve's FEM keeps up when it made most of its updates: 69-77 % of 1 050 on an idle machine
  // (its 24k-tet update takes 12-13 ms against its 10 ms period), 36-50 % beside stress-ng.
  const double fem_updates = b["fem"]["updates"].get<double>();
  const double fem_periods = 10.5 / (1e-3 * b["fem"]["period_steps"].get<double>());
  const bool fem_kept_up = fem_updates >= 0.6 * fem_periods;
  const double low = fem_kept_up ? 0.95 : 0.85;
  const double high = fem_kept_up ? 1.05 : 1.6;
  if (!fem_kept_up) {
    std::printf(
        "serve's FEM made %.0f of %.0f updates: this machine could not keep it in real "
        "time, so the forces are held to the served FEM block's bounds, not the 5 %%\n",
        fem_updates, fem_periods);
  }
  // The served world: the same presses through the master's joints, as hard as in one process.
  EXPECT_GE(b["peak_tool_force_n"].get<double>(), low * one_peak_n);
  EXPECT_LE(b["peak_tool_force_n"].get<double>(), high * one_peak_n);
  EXPECT_GE(b["peak_master_torque_nm"].get<double>(), low * one_torque_nm);
  EXPECT_LE(b["peak_master_torque_nm"].get<double>(), high * one_torque_nm);
  const double pace = test::serve_pace(serve.output());
  ASSERT_GT(pace, 0.0) << serve.output();
  const double one_contacts = a["tools"][0]["contact_steps"].get<double>();
  const double served_contacts = b["tools"][0]["contact_steps"].get<double>();
  // Both runs hold the master still after its script's 10.2 s, out of contact; serve steps by the
  // device's clock, and a serve behind real time counts a touch in fewer steps
  // (three_process_test.cpp).
  EXPECT_GE(served_contacts, 0.95 * std::min(pace, 1.0) * one_contacts - 1.0);
  EXPECT_LE(served_contacts, 1.05 * one_contacts + 1.0);
  // The master: the pad's models rendered at its own pose, felt through its joints, as the
  // one-process master felt the pad (4.520 against 4.518 N, 1.295 against 1.294 N·m, idle).
  // Before: 1.3x idle and up to 1.7x loaded, from two faults since fixed: the renderer's blend
  // stacked the pulls a step out of the tissue would have made (device/local_model_renderer.cpp),
  // and the master's script moved it in 0.2 mm steps (script/master_flange_ik.cpp).
  EXPECT_GE(d["peak_force_n"].get<double>(), low * one_peak_n);
  EXPECT_LE(d["peak_force_n"].get<double>(), high * one_peak_n);
  EXPECT_GE(d["peak_joint_torque_nm"].get<double>(), low * one_torque_nm);
  EXPECT_LE(d["peak_joint_torque_nm"].get<double>(), high * one_torque_nm);
  EXPECT_EQ(b["pop_throughs"].get<int>(), 0);
  EXPECT_EQ(b["serve"]["device_states"]["malformed"].get<int>(), 0);
  EXPECT_GT(b["serve"]["device_host_cycles"].get<int>(), 9'000);  // the master drove it all
  EXPECT_EQ(b["slave_collisions"]["steps"].get<int>(), 0);

  // The viewer saw the pad press: the carried tool's force in the view states is its contact
  // force (the master's command holds torques, no tip force), sampled at ~30 Hz, so below the
  // served peak and within the held presses' range of it.
  const nlohmann::json w = read_json(watch_json);
  EXPECT_LE(w["peak_force_n"].get<double>(), 1.05 * b["peak_tool_force_n"].get<double>());
  EXPECT_GE(w["peak_force_n"].get<double>(), 0.5 * one_peak_n);
  EXPECT_TRUE(std::filesystem::exists(watch_png));

  EXPECT_EQ(d["models"]["malformed"].get<int>(), 0);
  EXPECT_GT(d["models_rendered"].get<int>(), 5'000);
}

// The pick-and-place rig (scenes/teleop.json) served: the master's joints drive the served slave,
// which grasps the ball, carries it over and sets it on the sheet as in one process. Its end
// (where the ball lies, how high it was carried, the grasp's force) is compared, not its times:
// serve's clock starts before the device joins and a stalled cycle moves the slave in a jump, and
// one such jump loosened a pad for a step (the served summary's "release" at 6.000 s in the
// carry, the ball carried on: 0.45 mm from where one process leaves it). The master feels the
// grasp through the pads' served models (rig/pad_models.h): the grip on its fingers as one
// process's master does, and the ball's weight on the pads through its arm, compared as its mean
// over the hold (a stalled cycle jerks the served slave, and the 100 g ball between its pads takes
// that jerk as a one-step peak of up to 20 N in the served world, which no peak comparison
// survives; the master's rate limit smooths it).
TEST(RigServe, ServeAndMasterReproduceTheOneProcessPickAndPlace) {
  ASSERT_TRUE(test::on_loopback_config());
  const auto one_json = hapsim::test::temp_path("pick_one.json");
  const auto served_json = hapsim::test::temp_path("pick_served.json");
  const auto device_json = hapsim::test::temp_path("pick_device.json");
  const hapsim::test::RunResult one =
      hapsim::test::run_hapsim("run " + kPickAndPlace + " --quiet --json " + one_json.string());
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const std::string net = " --session rig-pick --domain 82";
  BackgroundHapsim serve("serve " + kPickAndPlace + " --wait-for-device --duration 11 --json " +
                             served_json.string() + net,
                         hapsim::test::temp_path("pick_serve.log"));
  ASSERT_TRUE(serve.wait_for("waiting", 60s)) << serve.output();
  // A headless viewer: it draws the served master, slave and grasp from the view states' rig part.
  const auto watch_json = hapsim::test::temp_path("pick_watch.json");
  const auto watch_png = hapsim::test::temp_path("pick_watch.png");
  BackgroundHapsim watch("watch --duration 12 --json " + watch_json.string() + " --snapshot " +
                             watch_png.string() + net,
                         hapsim::test::temp_path("pick_watch.log"));
  BackgroundHapsim device("device --duration 11.5" + net + " --json " + device_json.string(),
                          hapsim::test::temp_path("pick_device.log"));
  EXPECT_EQ(serve.wait(), 0) << serve.output();
  EXPECT_EQ(device.wait(), 0) << device.output();
  EXPECT_EQ(watch.wait(), 0) << watch.output();
  std::printf("%s\n%s\n", serve.output().c_str(), device.output().c_str());
  if (const std::string why = test::serve_too_slow_for_real_time(serve.output()); !why.empty()) {
    GTEST_SKIP() << why;
  }
  const nlohmann::json a = read_json(one_json);
  const nlohmann::json b = read_json(served_json);
  ASSERT_TRUE(a["grasped"].get<bool>());
  EXPECT_TRUE(b["grasped"].get<bool>()) << "the served slave should grasp the ball";
  const auto ball_one = a["ball_final_position_m"].get<std::array<double, 3>>();
  const auto ball_served = b["ball_final_position_m"].get<std::array<double, 3>>();
  const Vec3 end_one(ball_one[0], ball_one[1], ball_one[2]);
  const Vec3 end_served(ball_served[0], ball_served[1], ball_served[2]);
  // Carried 500 mm; set down where one process sets it (0.45 mm apart, idle).
  EXPECT_LT((end_served - end_one).norm(), 2e-3) << end_served.transpose();
  EXPECT_NEAR(b["ball_lift_m"].get<double>(), a["ball_lift_m"].get<double>(),
              0.05 * a["ball_lift_m"].get<double>());
  EXPECT_NEAR(b["peak_grasp_force_n"].get<double>(), a["peak_grasp_force_n"].get<double>(),
              0.05 * a["peak_grasp_force_n"].get<double>());
  EXPECT_EQ(b["slave_collisions"]["steps"].get<int>(), 0);
  EXPECT_EQ(b["serve"]["device_states"]["malformed"].get<int>(), 0);
  EXPECT_GT(b["serve"]["device_host_cycles"].get<int>(), 9'000);  // the master drove it all

  // The master felt the grasp: the grip on its fingers (20 N, the gripper's limit, in both) and
  // the ball on the pads through its arm, as one process's master: 0.894 N over 4.5 s of hold,
  // served 0.893-0.896 N idle, within 5 % as the knee's three-process test holds its forces.
  // A stalled serve or device cycle makes the served slave's target jump; the slave catches up
  // within its acceleration limit (SlaveFollower), where it used to take the jump in one cycle
  // and kick the ball with up to 20 N (served mean +4 to +78 % idle).
  const nlohmann::json d = read_json(device_json);
  EXPECT_NE(device.output().find("its gripper's pads on the ball felt"), std::string::npos);
  EXPECT_NEAR(d["peak_grasp_force_n"].get<double>(), a["peak_grasp_force_n"].get<double>(),
              0.05 * a["peak_grasp_force_n"].get<double>());
  const double one_held_n = a["mean_held_tool_force_n"].get<double>();
  EXPECT_NEAR(one_held_n, 0.98, 0.15);  // about the 100 g ball's weight (the floor bears some)
  EXPECT_NEAR(d["mean_held_force_n"].get<double>(), one_held_n, 0.05 * one_held_n);
  // The served world's own mean: within 10 % while its slave caught up on under 10 % of the
  // steps (idle: 1-6 %, +0 to +5 %). Beside stress-ng the device's cycles stall too, and its
  // script, on cycle time, pauses the master: the served slave stops and restarts at its limit
  // on every pause (18 % of the steps in one run, its mean +28 %), which the device's own master
  // never did.
  const double served_held_n = b["mean_held_tool_force_n"].get<double>();
  const double catching_up = b["slave_limited_steps"].get<double>() / b["steps"].get<double>();
  if (catching_up < 0.1) {
    EXPECT_NEAR(served_held_n, one_held_n, 0.1 * one_held_n);
  } else {
    std::printf(
        "the served slave caught up on %.0f %% of the steps: its world's mean over the "
        "hold is %.3f N against one process's %.3f N\n",
        100 * catching_up, served_held_n, one_held_n);
    EXPECT_NEAR(served_held_n, one_held_n, 0.5 * one_held_n);
  }
  // The one-process slave follows a smooth master: its limits never act. Served, a catch-up
  // accelerates the ball at most by the slave's 30 rad/s² over its 1 m reach, and the pads'
  // springs ring to twice that: 0.1 kg × 30 m/s² × 2 over the ball's weight, under 7 N (it was
  // 13-21 N before the limit; 1.5-4.6 N with it, idle).
  EXPECT_EQ(a["slave_limited_steps"].get<int>(), 0);
  EXPECT_LE(b["peak_tool_force_n"].get<double>(), 7.0);
  std::printf(
      "peak force at the slave's tool: one process %.3f N, served %.3f N (%d steps "
      "catching up), the master's %.3f N\n",
      a["peak_tool_force_n"].get<double>(), b["peak_tool_force_n"].get<double>(),
      b["slave_limited_steps"].get<int>(), d["peak_force_n"].get<double>());
  EXPECT_GE(d["held_cycles"].get<double>(), 0.9 * a["held_steps"].get<double>());
  EXPECT_LE(d["held_cycles"].get<double>(), 1.1 * a["held_steps"].get<double>());
  EXPECT_EQ(d["models"]["malformed"].get<int>(), 0);

  // The viewer saw the grasp in the view states' rig part (it drew the view at its peak).
  const nlohmann::json w = read_json(watch_json);
  EXPECT_EQ(w["refused"].get<int>(), 0);
  EXPECT_NEAR(w["peak_grasp_force_n"].get<double>(), a["peak_grasp_force_n"].get<double>(),
              0.05 * a["peak_grasp_force_n"].get<double>());
  EXPECT_TRUE(std::filesystem::exists(watch_png));
}

}  // namespace
}  // namespace hapsim::net
