// A running world's view over the network (net/view_state_codec.h): what a viewer decodes is what
// the simulation host had — tools, contacts, body poses and every deformed vertex, to float
// precision — whether it joined at the start or late; a vertex back at rest is put back; a sample
// that does not fit the viewer's world is refused whole, naming why, and changes nothing.
#include "hapsim/net/view_state_codec.h"
#include "hapsim/runtime/teleop_snapshot.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_file.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_procedural.json";
constexpr std::uint64_t kHash = 0x1234;

struct Served {
  explicit Served(const std::string& scene = kScene)
      : setup(make_run_setup(load_scene(scene), DeviceChoice::scene_script())) {}
  RunSetup setup;
  World& world = *setup.world;
  double t_s = 0.0;
};

// Steps the served world to `t_s` with its script.
void run_to(Served& s, double t_s) {
  const double dt = 0.001;
  for (; s.t_s < t_s; s.t_s += dt) {
    (void)s.world.step(s.setup.device->read(s.t_s), dt);
  }
}

// What the haptic client publishes of the world now (runtime/world_haptic_client.cpp): the
// surfaces, and the tools and contacts of the last step.
WorldSnapshot snapshot_of(const World& world) {
  WorldSnapshot s = make_world_snapshot(world);
  const WorldState& state = world.state();
  for (std::size_t t = 0; t < s.tools.size(); ++t) {
    s.tools[t] = state.tool_states[t];
    s.tool_force_n[t] = state.tool_states[t].force_world_n.norm();
  }
  s.contact_count = std::min(state.contact_count, s.contacts.size());
  std::copy_n(state.contacts.begin(), s.contact_count, s.contacts.begin());
  s.hand = world.hand_reading();
  return s;
}

float max_vertex_error_m(const WorldSnapshot& a, const WorldSnapshot& b) {
  float worst = 0.0f;
  for (std::size_t flat = 0; flat < a.positions_body.size(); ++flat) {
    for (std::size_t i = 0; i < a.positions_body[flat].size(); ++i) {
      worst = std::max(worst, std::abs(a.positions_body[flat][i] - b.positions_body[flat][i]));
    }
  }
  return worst;
}

TEST(ViewStateCodec, ALateViewerDrawsTheCurrentDentAndItsRelease) {
  Served host;
  ViewStateEncoder encoder(host.world);  // at rest
  Served viewer_side;                    // the viewer's own build of the scene
  WorldSnapshot seen = make_world_snapshot(viewer_side.world);
  ViewStateDecoder decoder(viewer_side.world);
  std::string why;

  run_to(host, 3.27);  // the patella press: the skin is dented ~10 mm
  WorldSnapshot truth = snapshot_of(host.world);
  const hapsim_msg_ViewState& m = encoder.encode(truth, kHash, 7, true);
  EXPECT_GT(m.offsets._length, 10u);
  EXPECT_LT(m.offsets._length, 5000u);  // only what moved, not all 14 394 vertices
  ASSERT_TRUE(decoder.decode(m, kHash, seen, why)) << why;
  EXPECT_LE(max_vertex_error_m(seen, truth), 1e-6f);
  ASSERT_GT(truth.contact_count, 0u);
  ASSERT_EQ(seen.contact_count, truth.contact_count);
  EXPECT_EQ(seen.contacts[0].segment, truth.contacts[0].segment);
  EXPECT_NEAR(seen.contacts[0].force_n, truth.contacts[0].force_n, 1e-12);
  EXPECT_GT(truth.tool_force_n[0], 5.0);
  EXPECT_NEAR(seen.tool_force_n[0], truth.tool_force_n[0], 1e-12);
  EXPECT_NEAR((seen.tools[0].p_world - truth.tools[0].p_world).norm(), 0.0, 1e-12);
  double deepest = 0.0;
  for (const double d : seen.deflection_m) {
    deepest = std::max(deepest, d);
  }
  EXPECT_GT(deepest, 0.001);

  // The finger lifts off: the vertices go back to rest in the viewer too.
  run_to(host, 3.9);
  truth = snapshot_of(host.world);
  ASSERT_TRUE(decoder.decode(encoder.encode(truth, kHash, 7, true), kHash, seen, why)) << why;
  EXPECT_LE(max_vertex_error_m(seen, truth), 1e-6f);
}

TEST(ViewStateCodec, RefusesWhatDoesNotFitTheWorldAndChangesNothing) {
  Served host;
  ViewStateEncoder encoder(host.world);
  run_to(host, 3.27);
  const WorldSnapshot truth = snapshot_of(host.world);
  WorldSnapshot seen = make_world_snapshot(host.world);
  const WorldSnapshot before = seen;
  ViewStateDecoder decoder(host.world);
  std::string why;

  hapsim_msg_ViewState m = encoder.encode(truth, kHash, 7, true);
  EXPECT_FALSE(decoder.decode(m, kHash + 1, seen, why));
  EXPECT_NE(why.find("another scene"), std::string::npos);

  ASSERT_GT(m.offsets._length, 0u);
  const hapsim_msg_VertexOffset saved = m.offsets._buffer[0];
  m.offsets._buffer[0].vertex = 1u << 30;
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("vertex offset"), std::string::npos) << why;
  m.offsets._buffer[0] = saved;
  m.offsets._buffer[0].offset_m[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  m.offsets._buffer[0] = saved;

  m.bodies._buffer[0].q_wxyz[0] = 3.0;  // not a rotation
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("rigid motion"), std::string::npos) << why;
  m = encoder.encode(truth, kHash, 7, true);
  ASSERT_GT(m.contacts._length, 0u);
  m.contacts._buffer[0].segment = 99;
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("segment the scene does not have"), std::string::npos) << why;
  m = encoder.encode(truth, kHash, 7, true);
  m.tool_count = 3;
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  m = encoder.encode(truth, kHash, 7, true);
  ASSERT_GT(m.deflection_m._length, 0u);
  m.deflection_m._buffer[0] = std::numeric_limits<float>::infinity();  // found by fuzz.view_state
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("deflection"), std::string::npos) << why;

  // Nothing of the refused samples reached the snapshot.
  EXPECT_EQ(max_vertex_error_m(seen, before), 0.0f);
  EXPECT_EQ(seen.contact_count, before.contact_count);
}

// A glove world's hand travels with the view, so a connected viewer draws the hand the host's
// glove holds (the fingers' angles, the tracker's pose), not one at rest; a non-finite hand is
// refused like any other non-finite number.
TEST(ViewStateCodec, CarriesTheGlovesHandAndRefusesANonFiniteOne) {
  const std::string scene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_hand_procedural.json";
  Served host(scene);
  ViewStateEncoder encoder(host.world);
  Served viewer_side(scene);
  WorldSnapshot seen = make_world_snapshot(viewer_side.world);
  ViewStateDecoder decoder(viewer_side.world);
  std::string why;

  run_to(host, 2.0);  // the hand has moved in and curled its fingers
  const WorldSnapshot truth = snapshot_of(host.world);
  double moved_rad = 0.0;
  for (const auto& finger : truth.hand.angles_rad) {
    for (const double a : finger) {
      moved_rad = std::max(moved_rad, std::abs(a));
    }
  }
  ASSERT_GT(moved_rad, 0.1) << "the script's hand never bent a finger: nothing to carry";
  hapsim_msg_ViewState m = encoder.encode(truth, kHash, 7, true);
  ASSERT_TRUE(decoder.decode(m, kHash, seen, why)) << why;
  for (std::size_t f = 0; f < truth.hand.angles_rad.size(); ++f) {
    for (std::size_t a = 0; a < truth.hand.angles_rad[f].size(); ++a) {
      EXPECT_EQ(seen.hand.angles_rad[f][a], truth.hand.angles_rad[f][a]) << f << "," << a;
    }
  }
  EXPECT_LE((seen.hand.X_world_hand.matrix() - truth.hand.X_world_hand.matrix()).norm(), 1e-12);
  // The fingertips the viewer computes from the carried hand are the host's tools.
  const auto tips = viewer_side.world.model().hand()->fingertips_world(seen.hand);
  const auto host_tips = host.world.model().hand()->fingertips_world(truth.hand);
  for (std::size_t f = 0; f < tips.size(); ++f) {
    EXPECT_LE((tips[f] - host_tips[f]).norm(), 1e-12) << "finger " << f;
  }

  const WorldSnapshot before = seen;
  m.hand_angles_rad[4] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("hand"), std::string::npos) << why;
  m = encoder.encode(truth, kHash, 7, true);
  m.hand_q_wxyz[0] = 2.0;  // not a rotation
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("hand"), std::string::npos) << why;
  EXPECT_EQ(seen.hand.angles_rad, before.hand.angles_rad);
}

// A rig's part: the viewer draws the served master and slave from their joints, as one process
// does (before, view states carried the rig's bodies only, and a connected viewer drew no master).
TEST(ViewStateCodec, CarriesTheRigsMasterSlaveAndGraspAndRefusesAForeignOne) {
  const std::string scene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/teleop.json";
  Served host(scene);
  ViewStateEncoder encoder(host.world);
  Served viewer_side(scene);
  WorldSnapshot seen = make_world_snapshot(viewer_side.world);
  ASSERT_TRUE(seen.teleop.has_value());
  ViewStateDecoder decoder(viewer_side.world);
  std::string why;

  run_to(host, 5.0);  // grasped at 3.946 s, carried since
  WorldSnapshot truth = snapshot_of(host.world);
  ASSERT_TRUE(truth.teleop.has_value());
  fill_teleop_snapshot(*truth.teleop, host.world);
  truth.teleop->output = host.world.last_result().command;
  const TeleopSnapshot& want = *truth.teleop;
  ASSERT_TRUE(want.held) << "the script should hold the ball at 5 s";
  ASSERT_GT(std::abs(want.master_joint_rad[0]) + std::abs(want.slave_q[0]), 0.1);
  hapsim_msg_ViewState m = encoder.encode(truth, kHash, 7, true);
  ASSERT_TRUE(decoder.decode(m, kHash, seen, why)) << why;
  const TeleopSnapshot& got = *seen.teleop;
  EXPECT_EQ(got.master_joint_rad, want.master_joint_rad);
  EXPECT_EQ(got.master_finger_rad, want.master_finger_rad);
  EXPECT_EQ(got.slave_q, want.slave_q);
  EXPECT_LE((got.X_world_tool.matrix() - want.X_world_tool.matrix()).norm(), 1e-12);
  // The hand is the viewer's own master's for those joints: the host's.
  EXPECT_LE((got.X_master_hand.matrix() - want.X_master_hand.matrix()).norm(), 1e-12);
  for (std::size_t j = 0; j < 5; ++j) {
    EXPECT_EQ(got.output.joint_torque_nm[j], want.output.joint_torque_nm[j]) << j;
  }
  EXPECT_EQ(got.pad_force_n, want.pad_force_n);
  EXPECT_DOUBLE_EQ(got.grasp_force_n, want.grasp_force_n);
  EXPECT_TRUE(got.held);
  EXPECT_EQ(got.gripper_width_m, want.gripper_width_m);
  EXPECT_EQ(got.sheet_depth_m, want.sheet_depth_m);

  // Another slave (a scene with a different robot), a non-finite joint, a pose that is no
  // rotation: refused whole, naming why.
  const TeleopSnapshot before = got;
  m.rig.slave_dof = 7;
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("slave with 7 joints"), std::string::npos) << why;
  m = encoder.encode(truth, kHash, 7, true);
  m.rig.master_joint_rad[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("rig"), std::string::npos) << why;
  m = encoder.encode(truth, kHash, 7, true);
  m.rig.tool_q_wxyz[0] = 2.0;
  EXPECT_FALSE(decoder.decode(m, kHash, seen, why));
  EXPECT_NE(why.find("rig"), std::string::npos) << why;
  EXPECT_EQ(seen.teleop->slave_q, before.slave_q);
}

}  // namespace
}  // namespace hapsim::net
