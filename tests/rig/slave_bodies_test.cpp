// The slave robot's own links (and the gripper's palm and stem) are kinematic bodies of the rig's
// world: each step they sit where the chain's forward kinematics puts its frames (checked against
// SerialChain::frames, and for boxes against the joint origins they join), they push the ball
// (away from the link, equal and opposite), and one inside the floor is counted as a slave
// collision.
#include "hapsim/rig/rig_controller.h"
#include "hapsim/rig/rig_world.h"
#include "hapsim/world/world.h"

#include "hapsim/kinematics/procedural_motoman.h"
#include "hapsim/scene/scene_file.h"
#include "hapsim/scene/teleop_setup.h"
#include "support/test_data.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

namespace hapsim {
namespace {

TeleopRigDescription procedural_rig() {
  TeleopRigDescription d;
  d.slave = std::make_shared<const SerialChain>(make_procedural_motoman());
  d.slave_start_rad = {0.3, -0.2, 0.4, 0.1, 0.5, -0.2};
  d.environment.floor_z_m = 0.0;
  d.environment.X_world_sheet = Iso3(Eigen::Translation3d(0.5, 0.25, 0.05));
  d.ball_start_world = Vec3(0.5, -0.25, 0.03);
  return d;
}

// The master swinging its base: the slave's target turns about the slave's z, and IK follows.
DeviceInput master(double base_rad) {
  DeviceInput in;
  in.joint_rad[0] = base_rad;
  in.joint_rad[1] = 0.3;
  in.joint_rad[2] = 0.6;
  in.joint_count = 3;
  in.finger_count = 2;
  return in;
}

Vec3 centroid_world(const World& world, std::size_t body) {
  const TriangleMesh& mesh = world.description().bodies[body].segments.front().mesh;
  Vec3 c = Vec3::Zero();
  for (const Vec3& v : mesh.vertices) {
    c += world.body_pose(body) * v;
  }
  return c / static_cast<double>(mesh.vertices.size());
}

std::size_t body_named(const World& world, const std::string& name) {
  const auto& bodies = world.description().bodies;
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    if (bodies[b].name == name) {
      return b;
    }
  }
  ADD_FAILURE() << "no body " << name;
  return 0;
}

TEST(SlaveBodies, ProceduralBoxLinksJoinTheJointOriginsAsTheArmMoves) {
  World world(rig_world(procedural_rig()));
  const SerialChain& chain = rig_state(world)->slave->chain();
  const auto& slave = rig_description(world.description())->slave_bodies;
  std::vector<Vec3> before(slave.size());
  for (int k = 0; k <= 400; ++k) {
    for (std::size_t l = 0; l < slave.size(); ++l) {
      before[l] = centroid_world(world, slave[l].body);
    }
    if (k > 0) {
      static_cast<void>(world.step(master(0.002 * k), 1e-3));
    }
    if (k % 200 != 0) {
      continue;
    }
    if (k > 0) {
      // Each body moves as its velocity and turn say (a material point's displacement over the
      // step, to first order in the step's small turn).
      for (std::size_t l = 0; l < slave.size(); ++l) {
        const Vec3 c = centroid_world(world, slave[l].body);
        const Vec3 moved_v = (c - before[l]) / 1e-3;
        const Vec3 v = world.state().bodies[slave[l].body].velocity_at(c, Vec3::Zero());
        EXPECT_LT((v - moved_v).norm(), 0.01 * moved_v.norm() + 1e-9) << "body " << l;
      }
    }
    // Independent: the joint origins from the chain's own forward kinematics.
    std::array<Iso3, kMaxChainJoints> frames;
    const Iso3 tool = chain.frames(rig_state(world)->slave->q(), frames);
    std::vector<Vec3> origins{Vec3::Zero()};
    for (int j = 0; j < chain.dof(); ++j) {
      origins.push_back(frames[static_cast<std::size_t>(j)].translation());
    }
    origins.push_back(tool.translation());
    std::vector<Vec3> midpoints;
    for (std::size_t j = 1; j < origins.size(); ++j) {
      if ((origins[j] - origins[j - 1]).norm() > 1e-6) {
        midpoints.push_back(0.5 * (origins[j] + origins[j - 1]));
      }
    }
    ASSERT_EQ(slave.size(), midpoints.size() + 2) << "links, then the palm and the stem";
    for (std::size_t l = 0; l < midpoints.size(); ++l) {
      EXPECT_EQ(world.description().bodies[slave[l].body].kind, BodyKind::kKinematic);
      EXPECT_LT((centroid_world(world, slave[l].body) - midpoints[l]).norm(), 1e-9)
          << "link box " << l << " at step " << k;
    }
    // The palm and the stem hang on the tool's axis, between the flange and the pads' tops.
    const ParallelGripperParams& g = rig_description(world.description())->gripper;
    for (const std::size_t b : {slave[midpoints.size()].body, slave[midpoints.size() + 1].body}) {
      const Vec3 c_tool = tool.inverse() * centroid_world(world, b);
      EXPECT_LT(c_tool.head<2>().norm(), 1e-9);
      EXPECT_GT(c_tool.z(), 0.0);
      EXPECT_LT(c_tool.z(), g.pad_depth_m - g.pad_half_m.z());
    }
  }
}

TEST(SlaveBodies, Gp7LinkBodiesAreItsCollisionMeshesAtTheirChainFrames) {
  const auto data = test::data_path("motoman_gp7");
  HAPSIM_SKIP_WITHOUT_DATA(std::filesystem::exists(data / "gp7.urdf"),
                           "Motoman GP7 URDF not found in " << data);
  SceneLoadOptions o;
  o.data_dir = data;
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop_gp7.json", o);
  const TeleopSetup setup = make_rig_setup(scene, std::nullopt, /*load_link_meshes=*/true);
  const SerialChain& chain = *rig_description(setup.description)->slave;
  ASSERT_FALSE(chain.link_geometry().empty());
  World world(setup.description);
  const Trajectory& t = setup.trajectory;
  for (int k = 1; k <= 300; ++k) {
    static_cast<void>(world.step(t.sample_at(t.start_time_s() + k * 1e-3), 1e-3));
  }
  std::array<Iso3, kMaxChainJoints> frames;
  static_cast<void>(chain.frames(rig_state(world)->slave->q(), frames));
  std::size_t links = 0;
  for (const ChainLinkGeometry& g : chain.link_geometry()) {
    if (g.mesh.empty()) {
      continue;
    }
    ++links;
    const std::size_t b = body_named(world, "slave_" + g.link);
    const Iso3 X_world_frame =
        g.frame < 0 ? Iso3::Identity() : frames[static_cast<std::size_t>(g.frame)];
    EXPECT_TRUE(world.body_pose(b).isApprox(X_world_frame * g.X_frame_mesh, 1e-12)) << g.link;
    EXPECT_EQ(world.description().bodies[b].segments.front().mesh.vertices.size(),
              g.mesh.vertices.size())
        << g.link;
  }
  EXPECT_EQ(rig_description(world.description())->slave_bodies.size(), links + 2);
}

TEST(SlaveBodies, ALinkSweptIntoTheRestingBallPushesItAway) {
  // A point the arm's links sweep through during a base swing, found on a dry run with the ball
  // far away (the middle of a link 0.4 s in); then the ball waits there, weightless and at rest,
  // and the swing comes to it.
  const auto swing = [](int k) { return master(0.8 * k * 1e-3); };
  TeleopRigDescription d = procedural_rig();
  d.ball.gravity_m_per_s2 = Vec3::Zero();
  d.ball_start_world = Vec3(3.0, 3.0, 3.0);
  Vec3 meet = Vec3::Zero();
  {
    World dry(rig_world(d));
    for (int k = 1; k <= 400; ++k) {
      static_cast<void>(dry.step(swing(k), 1e-3));
    }
    meet = centroid_world(dry, rig_description(dry.description())->slave_bodies[3].body);
  }
  d.ball_start_world = meet;
  World world(rig_world(d));
  const std::size_t ball = rig_description(world.description())->ball_body;
  BodyIndex link = kNoBody;  // the first body to touch the ball: one of the slave's links
  Vec3 link_velocity = Vec3::Zero();
  for (int k = 1; k <= 600; ++k) {
    const StepResult& r = world.step(swing(k), 1e-3);
    Vec3 on_ball_from_link = Vec3::Zero();
    bool link_contact = false;
    for (const BodyContact& c : r.body_contacts) {
      ASSERT_EQ(c.body, BodyIndex{ball});
      if (!link.valid()) {
        link = c.other_body;
        // The link's material point where the ball is, at first touch.
        link_velocity = r.bodies[link.index()].velocity_at(meet, Vec3::Zero());
      }
      if (c.other_body == link) {
        on_ball_from_link += c.force_world_n;
        link_contact = true;
      }
    }
    if (!link.valid()) {
      // At rest until a link arrives.
      EXPECT_EQ(world.body_pose(ball).translation(), meet) << "step " << k;
    }
    if (link_contact) {
      // Equal and opposite: what the link took is what it gave the ball.
      const Vec3& on_link = r.bodies[link.index()].force_world_n;
      EXPECT_LT((on_link + on_ball_from_link).norm(),
                1e-9 * std::max(1.0, on_ball_from_link.norm()))
          << "step " << k;
    }
  }
  ASSERT_TRUE(link.valid()) << "no link met the ball";
  const std::string& name = world.description().bodies[link.index()].name;
  EXPECT_EQ(name.rfind("slave_", 0), 0U) << name;
  ASSERT_GT(link_velocity.norm(), 0.05) << "the link should sweep";
  // Pushed ahead of the link, along the way it swept, by more than a centimetre.
  const Vec3 moved = world.body_pose(ball).translation() - meet;
  EXPECT_GT(moved.norm(), 0.01);
  EXPECT_GT(moved.dot(link_velocity.normalized()), 0.5 * moved.norm());
}

TEST(SlaveBodies, ALinkInsideTheFloorIsASlaveCollision) {
  // The same slave over a floor at its start (nothing hit), and under a floor raised to 0.5 m
  // (the upper arm inside it; the base and the link the first joint turns stand on the robot's
  // mount and are not counted).
  for (const double floor_z : {0.0, 0.5}) {
    TeleopRigDescription d = procedural_rig();
    d.environment.floor_z_m = floor_z;
    d.ball_start_world = Vec3(0.5, -0.25, floor_z + 0.03);
    World world(rig_world(d));
    const StepResult& r = world.step(master(0.0), 1e-3);
    const std::size_t floor = rig_description(world.description())->floor_body;
    if (floor_z == 0.0) {
      EXPECT_EQ(rig_result(r)->slave_collisions, 0);
      EXPECT_EQ(rig_result(r)->slave_collision_bodies, 0U);
    } else {
      EXPECT_GT(rig_result(r)->slave_collisions, 0);
      EXPECT_TRUE((rig_result(r)->slave_collision_bodies >> floor) & 1U);
      for (const TeleopRigDescription::SlaveBody& s :
           rig_description(world.description())->slave_bodies) {
        if (s.frame < 1 && s.frame != kToolFrame) {
          EXPECT_FALSE((rig_result(r)->slave_collision_bodies >> s.body) & 1U);
        }
      }
    }
  }
}

TEST(SlaveBodies, TheBallPressingThePalmIsFeltAtTheMaster) {
  // A weightless ball placed against the palm's underside, between the open pads: only the palm
  // touches it; the master feels that push (the palm is past the wrist, as the pads are). The
  // same ball beside the arm: nothing felt.
  const DeviceInput input = master(0.2);
  TeleopRigDescription d = procedural_rig();
  d.ball.gravity_m_per_s2 = Vec3::Zero();
  std::array<double, 3> felt{};
  for (const bool under_palm : {false, true}) {
    Iso3 tool = Iso3::Identity();
    {
      World dry(rig_world(d));
      for (int k = 0; k < 2; ++k) {
        static_cast<void>(dry.step(input, 1e-3));
      }
      tool = rig_state(dry)->result.slave_tool;
    }
    const ParallelGripperParams& g = d.gripper;
    // 2 mm into the palm, whose underside is the pads' top.
    const double depth_m = g.pad_depth_m - g.pad_half_m.z() + d.ball.radius_m - 0.002;
    d.ball_start_world = under_palm ? Vec3(tool * Vec3(0.0, 0.0, depth_m)) : Vec3(3.0, 3.0, 3.0);
    World world(rig_world(d));
    static_cast<void>(world.step(input, 1e-3));
    const StepResult& r = world.step(input, 1e-3);
    std::size_t palm_contacts = 0;
    for (const BodyContact& c : r.body_contacts) {
      EXPECT_EQ(world.description().bodies[c.other_body.index()].name, "slave_gripper_palm");
      ++palm_contacts;
    }
    EXPECT_EQ(palm_contacts, under_palm ? 1U : 0U);
    ASSERT_EQ(r.command.joint_count, 5);
    for (std::size_t j = 0; j < 3; ++j) {
      felt[j] = r.command.joint_torque_nm[j];
    }
    const double felt_nm = std::abs(felt[0]) + std::abs(felt[1]) + std::abs(felt[2]);
    if (under_palm) {
      EXPECT_GT(felt_nm, 1e-3);
    } else {
      EXPECT_EQ(felt_nm, 0.0);
    }
  }
}

TEST(SlaveBodies, ShippedPickAndPlaceHoldsTheBallWithThePadsAlone) {
  // The scripted master grasps low enough for the pads and high enough that the palm above them
  // clears the ball (the ball is taller than the pads): nothing of the slave but the pads touches
  // it, and the slave hits nothing.
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "teleop.json");
  const TeleopSetup setup = make_rig_setup(scene, std::nullopt, true);
  World world(setup.description);
  const TeleopRigDescription& rig = *rig_description(world.description());
  const Trajectory& t = setup.trajectory;
  const auto steps = static_cast<int>((t.end_time_s() - t.start_time_s()) / 1e-3);
  int pad_steps = 0;
  for (int k = 1; k <= steps; ++k) {
    const StepResult& r = world.step(t.sample_at(t.start_time_s() + k * 1e-3), 1e-3);
    ASSERT_EQ(rig_result(r)->slave_collisions, 0) << "at " << r.time_s << " s";
    for (const BodyContact& c : r.body_contacts) {
      const std::size_t other = c.other_body.index();
      const bool pad = other == rig.pad_body[0] || other == rig.pad_body[1];
      pad_steps += pad ? 1 : 0;
      EXPECT_TRUE(pad || other == rig.floor_body || other == rig.sheet_body)
          << world.description().bodies[other].name << " touches the ball at " << r.time_s << " s";
    }
  }
  EXPECT_GT(pad_steps, 1000) << "the pads should have held the ball";
}

}  // namespace
}  // namespace hapsim
