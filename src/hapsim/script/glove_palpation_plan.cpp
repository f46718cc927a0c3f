#include "hapsim/script/glove_palpation_plan.h"

#include "hapsim/core/error.h"
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/script/hand_pose.h"
#include "hapsim/script/palpation_aim.h"
#include "hapsim/script/palpation_trajectory.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {

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

}  // namespace hapsim
