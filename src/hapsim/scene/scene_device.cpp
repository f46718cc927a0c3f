#include "hapsim/scene/scene_device.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/error.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/script/trajectory.h"
#include "hapsim/kinematics/hand_model.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hapsim {
namespace {

std::size_t find_body(const World& world, const std::string& name) {
  const auto& bodies = world.description().bodies;
  if (name.empty() && bodies.size() == 1) {
    return 0;
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    if (bodies[b].name == name) {
      return b;
    }
  }
  throw Error("palpation target", "no body named '" + name + "'");
}

std::size_t find_segment(const World& world, std::size_t body, const std::string& name) {
  const auto& segments = world.description().bodies[body].segments;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (segments[s].name == name) {
      return s;
    }
  }
  throw Error("palpation target",
              "body '" + world.description().bodies[body].name + "' has no segment '" + name + "'");
}

// Exact rest-surface queries of a body's segments, built once per body: aiming must not depend on
// the world's (possibly approximate, near-surface-only) contact method.
class ExactBodies {
 public:
  explicit ExactBodies(const World& world) : world_(world) {}
  const std::vector<std::unique_ptr<MeshBvh>>& body(std::size_t b) {
    auto& bvhs = cache_[b];
    if (bvhs.empty()) {
      for (const SegmentDescription& s : world_.description().bodies[b].segments) {
        bvhs.push_back(std::make_unique<MeshBvh>(s.mesh));
      }
    }
    return bvhs;
  }

 private:
  const World& world_;
  std::map<std::size_t, std::vector<std::unique_ptr<MeshBvh>>> cache_;
};

PalpationAim aim(const World& world, const PalpationTargetDescription& target, ExactBodies& exact) {
  const std::size_t body = find_body(world, target.body);
  const std::size_t segment = find_segment(world, body, target.segment);
  const BodyDescription& bd = world.description().bodies[body];
  const TriangleMesh& mesh = bd.segments[segment].mesh;
  Vec3 centroid_body = Vec3::Zero();
  for (const Vec3& v : mesh.vertices) {
    centroid_body += v;
  }
  centroid_body /= static_cast<double>(mesh.vertex_count());
  const Vec3 centroid_world = bd.X_world_body * centroid_body;
  const double norm = target.from_world.norm();
  if (!(norm > 0.0) || !target.from_world.allFinite()) {
    throw Error("palpation target '" + target.segment + "'", "needs a non-zero 'from' direction");
  }
  const Vec3 from = target.from_world / norm;
  // Start outside everything of the body, then trace towards the centroid: each step moves by
  // the distance to the nearest surface, so no surface can be skipped.
  Box3 all;
  for (const SegmentDescription& s : bd.segments) {
    all.extend(s.mesh.bounds());
  }
  const double reach = 2.0 * all.diagonal().norm() + 0.1;
  Vec3 p = centroid_world + from * reach;
  const Iso3 X_body_world = bd.X_world_body.inverse();
  const std::string where = "palpation target '" + target.segment + "'";
  for (int iteration = 0; iteration < 10000; ++iteration) {
    double nearest = kInf;
    std::size_t nearest_segment = segment;
    for (std::size_t s = 0; s < bd.segments.size(); ++s) {
      const SurfacePoint sp = exact.body(body)[s]->closest_point(X_body_world * p);
      if (std::abs(sp.signed_distance) < nearest) {
        nearest = std::abs(sp.signed_distance);
        nearest_segment = s;
      }
    }
    if (nearest < 1e-6) {
      return PalpationAim{p, nearest_segment};
    }
    p -= from * nearest;
    if ((p - centroid_world).dot(from) < 0.0) {
      break;  // passed the centroid without meeting a surface
    }
  }
  throw Error(where, "no surface of body '" + bd.name + "' lies between the direction " +
                         "given and the segment's centroid");
}

}  // namespace

PalpationAim aim_palpation_target(const World& world, const PalpationTargetDescription& target) {
  ExactBodies exact(world);
  return aim(world, target, exact);
}

PalpationPlan make_scene_palpation(const World& world, const PalpationScriptDescription& script) {
  if (script.targets.empty()) {
    throw Error("palpation script", "has no targets");
  }
  const double radius =
      world.description().tools.empty() ? 0.0 : world.description().tools.front().radius_m;
  std::vector<PalpationTarget> targets;
  ExactBodies exact(world);
  for (const PalpationTargetDescription& t : script.targets) {
    const PalpationAim aimed = aim(world, t, exact);
    const Vec3 from = t.from_world.normalized();
    PalpationTarget target;
    target.p_world = aimed.surface_world + from * radius;  // the tool sphere just touching
    target.press_dir_world = -from;
    target.depth_m = t.depth_m;
    target.hold_s = t.hold_s;
    targets.push_back(target);
  }
  PalpationParams params;
  params.standoff_m = script.standoff_m;
  params.move_s = script.move_s;
  params.approach_s = script.approach_s;
  params.press_s = script.press_s;
  params.release_s = script.release_s;
  if (script.has_around_axis) {
    // The cylinder round the axis through the centre of the targeted bodies that clears every
    // vertex of them, plus the farthest tool sphere from the device point, plus the stand-off.
    const Vec3 axis = script.around_axis_world.normalized();
    std::vector<std::size_t> bodies;
    for (const PalpationTargetDescription& t : script.targets) {
      bodies.push_back(find_body(world, t.body));
    }
    std::sort(bodies.begin(), bodies.end());
    bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
    Box3 box;
    for (const std::size_t b : bodies) {
      const BodyDescription& body = world.description().bodies[b];
      for (const SegmentDescription& seg : body.segments) {
        for (const Vec3& v : seg.mesh.vertices) {
          box.extend(body.X_world_body * v);
        }
      }
    }
    const Vec3 c = box.center();
    double body_r = 0.0;
    for (const std::size_t b : bodies) {
      const BodyDescription& body = world.description().bodies[b];
      for (const SegmentDescription& seg : body.segments) {
        for (const Vec3& v : seg.mesh.vertices) {
          const Vec3 d = body.X_world_body * v - c;
          body_r = std::max(body_r, (d - d.dot(axis) * axis).norm());
        }
      }
    }
    double tool_r = 0.0;
    for (const ToolDescription& tool : world.description().tools) {
      tool_r = std::max(tool_r, tool.offset_device.norm() + tool.radius_m);
    }
    params.around_point_world = c;
    params.around_axis_world = axis;
    params.around_radius_m = body_r + tool_r + script.standoff_m;
  }
  const Vec3 first_from = script.targets.front().from_world.normalized();
  params.start_p_world = targets.front().p_world + first_from * (script.standoff_m + 0.03);
  return make_palpation_plan(targets, params);
}

namespace {

// Glove angles (abduction, MCP, PIP) putting finger f's tip at `goal_hand` (hand frame): damped
// Gauss–Newton on the three angles with the DIP coupled, from a slightly curled start.
std::array<double, kGloveAnglesPerFinger> reach_with_finger(const HandModel& hand, int f,
                                                            const Vec3& goal_hand,
                                                            double* residual_m) {
  std::array<double, kGloveAnglesPerFinger> a{0.0, 0.35, 0.45};
  // Returns a Vec3, not `auto`: translation() is a view into the temporary transform, which is gone
  // when the lambda returns (a stack-use-after-return under AddressSanitizer).
  const auto tip = [&](const std::array<double, kGloveAnglesPerFinger>& angles) -> Vec3 {
    return hand.finger(f).forward(hand.finger_joints(f, angles)).translation();
  };
  for (int it = 0; it < 60; ++it) {
    const Vec3 e = goal_hand - tip(a);
    if (e.norm() < 1e-7) {
      break;
    }
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) {
      auto b = a;
      b[static_cast<std::size_t>(k)] += 1e-6;
      J.col(k) = (tip(b) - tip(a)) / 1e-6;
    }
    const Vec3 step =
        (J.transpose() * J + 1e-6 * Eigen::Matrix3d::Identity()).ldlt().solve(J.transpose() * e);
    for (int k = 0; k < 3; ++k) {
      a[static_cast<std::size_t>(k)] += std::clamp(step[k], -0.2, 0.2);
    }
    a = [&] {  // stay inside the joint limits the hand applies
      const auto q = hand.finger_joints(f, a);
      return std::array<double, kGloveAnglesPerFinger>{q[0], q[1], q[2]};
    }();
  }
  *residual_m = (goal_hand - tip(a)).norm();
  return a;
}

}  // namespace

Trajectory make_scene_glove_palpation(const World& world, const GlovePalpationDescription& g) {
  const char* where = "glove palpation";
  const WorldDescription& wd = world.description();
  const HandModel hand(wd.hand);
  const Vec3 from = g.from_world.normalized();
  // 1. Where each chosen fingertip's centre must be when pressed.
  std::vector<Vec3> goals;
  for (const GloveFingerTarget& t : g.fingers) {
    PalpationTargetDescription aim_at;
    aim_at.body = t.body;
    aim_at.segment = t.segment;
    aim_at.from_world = from;
    const Vec3 surface = aim_palpation_target(world, aim_at).surface_world;
    double radius = 0.0;
    for (const ToolDescription& tool : wd.tools) {
      if (tool.finger == t.finger) {
        radius = tool.radius_m;
      }
    }
    goals.push_back(surface + from * (radius - g.depth_m));
  }
  // 2. Hand orientation: back of the hand towards `from`, spread along the first two targets
  // (the finger nearer the thumb on the hand's +y side).
  const Vec3 z = from;
  Vec3 y = z.unitOrthogonal();
  if (goals.size() >= 2) {
    const bool first_is_thumbward = g.fingers[0].finger < g.fingers[1].finger;
    Vec3 d = first_is_thumbward ? Vec3(goals[0] - goals[1]) : Vec3(goals[1] - goals[0]);
    d -= d.dot(z) * z;
    if (d.norm() > 1e-6) {
      y = d.normalized();
    }
  }
  Mat3 R;
  R.col(0) = y.cross(z);
  R.col(1) = y;
  R.col(2) = z;
  // 3. Hand position: the chosen fingertips' centroid (slightly curled) on the goals' centroid.
  Vec3 tips_local = Vec3::Zero();
  Vec3 goals_centroid = Vec3::Zero();
  for (std::size_t i = 0; i < g.fingers.size(); ++i) {
    const int f = g.fingers[i].finger;
    tips_local += hand.finger(f).forward(hand.finger_joints(f, {0.0, 0.35, 0.45})).translation();
    goals_centroid += goals[i];
  }
  tips_local /= static_cast<double>(g.fingers.size());
  goals_centroid /= static_cast<double>(g.fingers.size());
  Vec3 p_press = goals_centroid - R * tips_local;
  // 4. Each chosen finger's angles to its goal, the hand shifted by the fingers' mean miss and
  // the angles solved again (a few rounds); the other fingers curled out of the way.
  std::array<std::array<double, kGloveAnglesPerFinger>, kHandFingers> angles{};
  for (int f = 0; f < kHandFingers; ++f) {
    angles[static_cast<std::size_t>(f)] = {0.0, 1.4, 1.7};
  }
  double worst = kInf;
  std::size_t worst_finger = 0;
  for (int round = 0; round < 20 && worst > 1e-4; ++round) {
    Iso3 X_press = Iso3::Identity();
    X_press.linear() = R;
    X_press.translation() = p_press;
    Vec3 miss = Vec3::Zero();
    worst = 0.0;
    for (std::size_t i = 0; i < g.fingers.size(); ++i) {
      const int f = g.fingers[i].finger;
      double residual = 0.0;
      angles[static_cast<std::size_t>(f)] =
          reach_with_finger(hand, f, X_press.inverse() * goals[i], &residual);
      const Vec3 tip =
          X_press * hand.finger(f)
                        .forward(hand.finger_joints(f, angles[static_cast<std::size_t>(f)]))
                        .translation();
      miss += goals[i] - tip;
      if (residual > worst) {
        worst = residual;
        worst_finger = i;
      }
    }
    p_press += miss / static_cast<double>(g.fingers.size());
  }
  if (worst > 1e-3) {
    throw Error(where, "finger " + std::to_string(g.fingers[worst_finger].finger) +
                           " cannot reach segment '" + g.fingers[worst_finger].segment +
                           "' from a common hand pose (off by " + std::to_string(worst * 1e3) +
                           " mm); press fewer or nearer segments");
  }
  // 5. In along −from, press, hold, back out.
  const Vec3 out_standoff = from * (g.standoff_m + g.depth_m);
  const Vec3 p_far = p_press + out_standoff + from * 0.05;
  const Vec3 p_stand = p_press + out_standoff;
  std::vector<DeviceInput> samples;
  const auto push = [&](double t, const Vec3& p) {
    DeviceInput in;
    in.time_s = t;
    in.p_world = p;
    in.q_world = Quat(R);
    in.joint_count = kHandFingers * kGloveAnglesPerFinger;
    for (int f = 0; f < kHandFingers; ++f) {
      for (int k = 0; k < kGloveAnglesPerFinger; ++k) {
        in.joint_rad[static_cast<std::size_t>(f * kGloveAnglesPerFinger + k)] =
            angles[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
      }
    }
    samples.push_back(in);
  };
  double t = 0.0;
  push(t, p_far);
  const auto ramp = [&](const Vec3& a, const Vec3& b, double duration) {
    const int n = std::max(1, static_cast<int>(std::ceil(duration / 0.001)));
    for (int k = 1; k <= n; ++k) {
      push(t + duration * k / n, a + (b - a) * minimum_jerk(static_cast<double>(k) / n));
    }
    t += duration;
  };
  ramp(p_far, p_stand, g.move_s);
  ramp(p_stand, p_press, g.press_s);
  if (g.hold_s > 0.0) {
    ramp(p_press, p_press, g.hold_s);
  }
  ramp(p_press, p_stand, g.release_s);
  return make_trajectory(std::move(samples), 0, kHandFingers * kGloveAnglesPerFinger, where);
}

std::unique_ptr<SimulatedDevice> make_scene_device(
    const SceneDescription& scene, const World& world,
    const std::optional<std::filesystem::path>& trajectory_override) {
  const DeviceProfile& profile = device_profile(scene.device.profile);
  if (trajectory_override) {
    return std::make_unique<SimulatedDevice>(profile, load_trajectory_csv(*trajectory_override));
  }
  if (!scene.device.trajectory_file.empty()) {
    return std::make_unique<SimulatedDevice>(profile,
                                             load_trajectory_csv(scene.device.trajectory_file));
  }
  if (scene.device.has_palpation) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_palpation(world, scene.device.palpation).trajectory);
  }
  if (scene.device.has_glove_palpation) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_glove_palpation(world, scene.device.glove_palpation));
  }
  throw Error(scene.file.string() + ": /device",
              "expected a 'trajectory' file or a 'palpation' script for the simulated device");
}

}  // namespace hapsim
