#include "hapsim/scene/scene_device.h"

#include "hapsim/collision/mesh_bvh.h"
#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/scene/glove_calibration_file.h"
#include "hapsim/script/trajectory.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
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
  const BodyDescription& bd = world.description().bodies[body];
  std::size_t segment = 0;
  Vec3 centroid_world;
  if (target.toward_world) {
    centroid_world = *target.toward_world;
    if (!target.segment.empty()) {
      segment = find_segment(world, body, target.segment);
    }
  } else {
    segment = find_segment(world, body, target.segment);
    const TriangleMesh& mesh = bd.segments[segment].mesh;
    Vec3 centroid_body = Vec3::Zero();
    for (const Vec3& v : mesh.vertices) {
      centroid_body += v;
    }
    centroid_body /= static_cast<double>(mesh.vertex_count());
    centroid_world = bd.X_world_body * centroid_body;
  }
  const std::string where =
      "palpation target '" + (target.segment.empty() ? target.body : target.segment) + "'";
  const double norm = target.from_world.norm();
  if (!(norm > 0.0) || !target.from_world.allFinite()) {
    throw Error(where, "needs a non-zero 'from' direction");
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
                         "given and " +
                         (target.toward_world ? "the point toward_m" : "the segment's centroid"));
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
  params.sample_period_s = script.sample_period_s;
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

using GloveAngles = std::array<double, kGloveAnglesPerFinger>;

// One glove sample: the tracker at `p_world` turned by R, every finger's three angles.
DeviceInput glove_input(double time_s, const Vec3& p_world, const Mat3& R,
                        const std::array<GloveAngles, kHandFingers>& angles) {
  DeviceInput in;
  in.time_s = time_s;
  in.p_world = p_world;
  in.q_world = Quat(R);
  in.joint_count = kHandFingers * kGloveAnglesPerFinger;
  for (int f = 0; f < kHandFingers; ++f) {
    for (int k = 0; k < kGloveAnglesPerFinger; ++k) {
      in.joint_rad[static_cast<std::size_t>(f) * kGloveAnglesPerFinger +
                   static_cast<std::size_t>(k)] =
          angles[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
    }
  }
  return in;
}

struct HandPoseSolution {
  Vec3 p_world = Vec3::Zero();
  std::array<GloveAngles, kHandFingers> angles{};
  double worst_m = 0.0;         ///< the largest fingertip miss
  std::size_t worst_index = 0;  ///< which of the listed fingers missed most
};

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

// The hand position and the listed fingers' glove angles that put each finger's tip centre on its
// goal (world) with the hand turned by R; the other fingers curled out of the way. The fingertips'
// centroid (slightly curled) starts on the goals' centroid; then each finger's angles are solved,
// the hand shifted by the fingers' mean miss, and the angles solved again (a few rounds).
HandPoseSolution solve_hand_pose(const HandModel& hand, const Mat3& R,
                                 const std::vector<int>& fingers, const std::vector<Vec3>& goals) {
  Vec3 tips_local = Vec3::Zero();
  Vec3 goals_centroid = Vec3::Zero();
  for (std::size_t i = 0; i < fingers.size(); ++i) {
    const int f = fingers[i];
    tips_local += hand.finger(f).forward(hand.finger_joints(f, {0.0, 0.35, 0.45})).translation();
    goals_centroid += goals[i];
  }
  tips_local /= static_cast<double>(fingers.size());
  goals_centroid /= static_cast<double>(fingers.size());
  HandPoseSolution out;
  out.p_world = goals_centroid - R * tips_local;
  for (int f = 0; f < kHandFingers; ++f) {
    out.angles[static_cast<std::size_t>(f)] = {0.0, 1.4, 1.7};
  }
  out.worst_m = kInf;
  for (int round = 0; round < 20 && out.worst_m > 1e-4; ++round) {
    Iso3 X_press = Iso3::Identity();
    X_press.linear() = R;
    X_press.translation() = out.p_world;
    Vec3 miss = Vec3::Zero();
    out.worst_m = 0.0;
    for (std::size_t i = 0; i < fingers.size(); ++i) {
      const int f = fingers[i];
      double residual = 0.0;
      out.angles[static_cast<std::size_t>(f)] =
          reach_with_finger(hand, f, X_press.inverse() * goals[i], &residual);
      const Vec3 tip =
          X_press * hand.finger(f)
                        .forward(hand.finger_joints(f, out.angles[static_cast<std::size_t>(f)]))
                        .translation();
      miss += goals[i] - tip;
      if (residual > out.worst_m) {
        out.worst_m = residual;
        out.worst_index = i;
      }
    }
    out.p_world += miss / static_cast<double>(fingers.size());
  }
  return out;
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
    aim_at.toward_world = t.toward_world;
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
  const Vec3& z = from;
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
  // 3-4. Hand position and the chosen fingers' angles.
  std::vector<int> fingers;
  for (const GloveFingerTarget& t : g.fingers) {
    fingers.push_back(t.finger);
  }
  const HandPoseSolution solved = solve_hand_pose(hand, R, fingers, goals);
  if (solved.worst_m > 1e-3) {
    throw Error(where, "finger " + std::to_string(g.fingers[solved.worst_index].finger) +
                           " cannot reach its target (" +
                           (g.fingers[solved.worst_index].segment.empty()
                                ? std::string("the point toward_m")
                                : "segment '" + g.fingers[solved.worst_index].segment + "'") +
                           ") from a common hand pose (off by " +
                           std::to_string(solved.worst_m * 1e3) +
                           " mm); press fewer or nearer segments");
  }
  const Vec3 p_press = solved.p_world;
  const auto& angles = solved.angles;
  // 5. In along −from, press, hold, back out.
  const Vec3 out_standoff = from * (g.standoff_m + g.depth_m);
  const Vec3 p_far = p_press + out_standoff + from * 0.05;
  const Vec3 p_stand = p_press + out_standoff;
  std::vector<DeviceInput> samples;
  const auto push = [&](double t, const Vec3& p) {
    samples.push_back(glove_input(t, p, R, angles));
  };
  double t = 0.0;
  push(t, p_far);
  const auto ramp = [&](const Vec3& a, const Vec3& b, double duration) {
    const int n = std::max(1, static_cast<int>(std::ceil(duration / g.sample_period_s)));
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

Trajectory make_scene_glove_pick_and_place(const World& world,
                                           const GlovePickAndPlaceDescription& g) {
  const std::string where = "glove pick-and-place";
  const WorldDescription& wd = world.description();
  const HandModel hand(wd.hand);
  const std::size_t ball = find_body(world, g.ball);
  const std::size_t sheet = find_body(world, g.sheet);
  const BodyDescription& ball_d = wd.bodies[ball];
  if (ball_d.kind != BodyKind::kDynamic || ball_d.segments.size() != 1 ||
      !ball_d.segments.front().sphere) {
    throw Error(where, "body '" + ball_d.name + "' is not a dynamic sphere (a ball)");
  }
  const BodyDescription& sheet_d = wd.bodies[sheet];
  if (world.sheet(sheet) == nullptr) {
    throw Error(where, "body '" + sheet_d.name + "' is not a sheet (deformation \"sheet\")");
  }
  for (const double d : {g.approach_s, g.close_s, g.lift_s, g.carry_s, g.lower_s, g.press_s,
                         g.open_s, g.retreat_s, g.settle_s}) {
    if (!(d > 0.0) || !std::isfinite(d)) {
      throw Error(where, "every phase needs a duration > 0 s");
    }
  }
  double tip_r[2] = {-1.0, -1.0};  // thumb, index
  for (const ToolDescription& t : wd.tools) {
    if (t.finger == 0 || t.finger == 1) {
      tip_r[t.finger] = t.radius_m;
    }
  }
  if (!wd.has_hand || tip_r[0] < 0.0 || tip_r[1] < 0.0) {
    throw Error(where, "needs a glove with thumb (finger 0) and index (finger 1) tools");
  }
  const ExactSphere& sphere = *ball_d.segments.front().sphere;
  const double R = sphere.radius_m;
  const Vec3 c_pick = ball_d.X_world_body * sphere.center_body;
  // Palm down (hand z up), fingers along world x. The pinch line is horizontal; the direction
  // the two fingertips reach best from one hand pose is searched.
  const Mat3 R_hand = Mat3::Identity();
  const std::vector<int> fingers{0, 1};
  const auto goals_at = [&](const Vec3& c, const Vec3& u, double extra) {
    return std::vector<Vec3>{c + (R + tip_r[0] - g.squeeze_m + extra) * u,
                             c - (R + tip_r[1] - g.squeeze_m + extra) * u};
  };
  HandPoseSolution pinch;
  pinch.worst_m = kInf;
  Vec3 u_best = Vec3::UnitY();
  for (int k = 0; k < 24; ++k) {
    const double a = k * std::numbers::pi / 12.0;
    const Vec3 u(std::cos(a), std::sin(a), 0.0);
    HandPoseSolution s = solve_hand_pose(hand, R_hand, fingers, goals_at(c_pick, u, 0.0));
    if (s.worst_m < pinch.worst_m) {
      pinch = s;
      u_best = u;
    }
  }
  if (pinch.worst_m > 1e-3) {
    throw Error(where, "thumb and index cannot pinch a ball of radius " + std::to_string(R * 1e3) +
                           " mm from one hand pose (off by " + std::to_string(pinch.worst_m * 1e3) +
                           " mm)");
  }
  // The open hand: the same hand position, the fingertips further out on the same line.
  Iso3 X_pinch = Iso3::Identity();
  X_pinch.linear() = R_hand;
  X_pinch.translation() = pinch.p_world;
  auto open = pinch.angles;
  const std::vector<Vec3> open_goals = goals_at(c_pick, u_best, g.open_clearance_m);
  for (std::size_t i = 0; i < 2; ++i) {
    const int f = fingers[i];
    double residual = 0.0;
    open[static_cast<std::size_t>(f)] =
        reach_with_finger(hand, f, X_pinch.inverse() * open_goals[i], &residual);
    const Vec3 tip =
        X_pinch * hand.finger(f)
                      .forward(hand.finger_joints(f, open[static_cast<std::size_t>(f)]))
                      .translation();
    if ((tip - c_pick).norm() < R + tip_r[i] + 0.25 * g.open_clearance_m) {
      throw Error(where, "finger " + std::to_string(f) + " cannot open clear of the ball");
    }
  }
  // Where the ball goes: over the sheet's point, its bottom press_depth_m below the rest surface.
  const Iso3& X_world_sheet = sheet_d.X_world_body;
  const Vec3 up_sheet = X_world_sheet.linear().col(2);
  const Vec3 place_surface = X_world_sheet * Vec3(g.place_sheet.x(), g.place_sheet.y(), 0.0);
  const Vec3 c_press = place_surface + (R - g.press_depth_m) * up_sheet;
  const Vec3 lift_up = Vec3(0.0, 0.0, g.lift_m);
  const Vec3 hand_from_ball = pinch.p_world - c_pick;
  const Vec3 p_grasp = pinch.p_world;
  const Vec3 p_above_pick = p_grasp + lift_up + Vec3(0.0, 0.0, R);
  const Vec3 p_press = c_press + hand_from_ball;
  const Vec3 p_above_place(p_press.x(), p_press.y(),
                           std::max(p_above_pick.z(), p_press.z() + g.press_depth_m + g.lift_m));

  std::vector<DeviceInput> samples;
  double t = 0.0;
  const auto push = [&](double time_s, const Vec3& p,
                        const std::array<GloveAngles, kHandFingers>& angles) {
    samples.push_back(glove_input(time_s, p, R_hand, angles));
  };
  Vec3 p_now = p_above_pick;
  auto angles_now = open;
  push(t, p_now, angles_now);
  // Move the hand to `p` and the fingers to `angles` together, minimum jerk, in `duration` s.
  const auto move = [&](const Vec3& p, const std::array<GloveAngles, kHandFingers>& angles,
                        double duration) {
    const int n = std::max(1, static_cast<int>(std::ceil(duration / g.sample_period_s)));
    for (int k = 1; k <= n; ++k) {
      const double s = minimum_jerk(static_cast<double>(k) / n);
      std::array<GloveAngles, kHandFingers> a{};
      for (std::size_t f = 0; f < a.size(); ++f) {
        for (std::size_t j = 0; j < a[f].size(); ++j) {
          a[f][j] = angles_now[f][j] + (angles[f][j] - angles_now[f][j]) * s;
        }
      }
      push(t + duration * k / n, p_now + (p - p_now) * s, a);
    }
    t += duration;
    p_now = p;
    angles_now = angles;
  };
  move(p_grasp, open, g.approach_s);           // down around the ball, fingers open
  move(p_grasp, pinch.angles, g.close_s);      // pinch
  move(p_grasp, pinch.angles, 0.2);            // let the grip settle
  move(p_above_pick, pinch.angles, g.lift_s);  // lift
  move(p_above_place, pinch.angles, g.carry_s);
  move(p_press, pinch.angles, g.lower_s);  // into the sheet
  move(p_press, pinch.angles, g.press_s);  // hold the press
  move(p_press, open, g.open_s);           // let go
  move(p_press + Vec3(0.0, 0.0, R + g.lift_m), open, g.retreat_s);
  move(p_now, open, g.settle_s);  // watch the ball settle
  return make_trajectory(std::move(samples), 0, kHandFingers * kGloveAnglesPerFinger, where);
}

Trajectory load_device_trajectory(const SceneDescription& scene,
                                  const std::filesystem::path& file) {
  if (scene.device.type == "glove") {
    const DeviceDescription& d = scene.device;
    return load_glove_trajectory(file, d.glove_calibration ? &*d.glove_calibration : nullptr,
                                 d.glove_calibration_file);
  }
  Trajectory t = load_trajectory_csv(file);
  if (t.sensor_count > 0) {
    throw Error(file.string(),
                "has raw glove sensor columns s0..; only a \"glove\" device with a "
                "\"calibration\" plays them");
  }
  return t;
}

std::unique_ptr<SimulatedDevice> make_scene_device(
    const SceneDescription& scene, const World& world,
    const std::optional<std::filesystem::path>& trajectory_override) {
  const DeviceProfile& profile = device_profile(scene.device.profile);
  if (trajectory_override || !scene.device.trajectory_file.empty()) {
    const std::filesystem::path& file =
        trajectory_override ? *trajectory_override : scene.device.trajectory_file;
    return std::make_unique<SimulatedDevice>(profile, load_device_trajectory(scene, file));
  }
  if (scene.device.has_palpation) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_palpation(world, scene.device.palpation).trajectory);
  }
  if (scene.device.has_glove_palpation) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_glove_palpation(world, scene.device.glove_palpation));
  }
  if (scene.device.has_glove_pick_and_place) {
    return std::make_unique<SimulatedDevice>(
        profile, make_scene_glove_pick_and_place(world, scene.device.glove_pick_and_place));
  }
  throw Error(scene.file.string() + ": /device",
              "expected a 'trajectory' file or a 'palpation' script for the simulated device");
}

}  // namespace hapsim
