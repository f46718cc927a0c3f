#include "hapsim/script/glove_pick_and_place_plan.h"

#include "hapsim/core/error.h"
#include "hapsim/kinematics/hand_model.h"
#include "hapsim/script/hand_pose.h"
#include "hapsim/script/palpation_aim.h"
#include "hapsim/script/palpation_trajectory.h"
#include "hapsim/world/world.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace hapsim {

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

}  // namespace hapsim
