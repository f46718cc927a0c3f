#include "hapsim/script/pick_and_place_trajectory.h"

#include "hapsim/core/error.h"
#include "hapsim/script/master_flange_ik.h"
#include "hapsim/script/palpation_trajectory.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hapsim {

namespace {

struct Waypoint {
  const char* phase;
  double duration_s;
  Vec3 flange_world;
  double width_m;
  bool circle = false;  // explore: go round the centre instead of a straight line
};

}  // namespace

double grasp_depth_m(double pad_depth_m, double pad_half_height_m, double ball_radius_m,
                     double clearance_m) {
  // The palm's underside is the pads' top, pad_depth − half below the flange; the ball's top is
  // its radius above its centre.
  return pad_depth_m + std::max(0.0, ball_radius_m + clearance_m - pad_half_height_m);
}

PickAndPlacePlan make_pick_and_place_plan(const PickAndPlaceScript& s, const MasterArm& master,
                                          const TeleopMapping& mapping, double slave_max_width_m) {
  const char* where = "pick-and-place script";
  for (const double d : {s.hover_s, s.explore_s, s.descend_s, s.close_s, s.lift_s, s.carry_s,
                         s.lower_s, s.open_s, s.retreat_s, s.settle_s, s.sample_period_s}) {
    if (!(d > 0.0) || !std::isfinite(d)) {
      throw Error(where, "durations must be > 0 s");
    }
  }
  const Vec3 up = Vec3::UnitZ();
  const Vec3 above_pick = s.pick_world + up * (s.grasp_depth_m + s.clearance_m);
  const Vec3 at_pick = s.pick_world + up * s.grasp_depth_m;
  const Vec3 above_place = s.place_world + up * (s.grasp_depth_m + s.clearance_m);
  const Vec3 at_place = s.place_world + up * (s.grasp_depth_m + s.release_height_m);
  const std::vector<Waypoint> plan{
      {"hover", s.hover_s, above_pick, s.open_width_m},
      {"explore", s.explore_s, above_pick, s.open_width_m, true},
      {"descend", s.descend_s, at_pick, s.open_width_m},
      {"close", s.close_s, at_pick, s.closed_width_m},
      {"lift", s.lift_s, above_pick, s.closed_width_m},
      {"carry", s.carry_s, above_place, s.closed_width_m},
      {"lower", s.lower_s, at_place, s.closed_width_m},
      {"open", s.open_s, at_place, s.open_width_m},
      {"retreat", s.retreat_s, above_place, s.open_width_m},
      {"settle", s.settle_s, above_place, s.open_width_m},
  };

  // Slave flange → master hand (inverse of the mapping) → master joints (position IK, tracked).
  MasterFlangeIk ik(master, mapping, slave_max_width_m, where);
  auto sample = [&](double t, const Vec3& flange, double width) {
    return ik.input_for(t, flange, width);
  };

  PickAndPlacePlan out;
  out.first_flange_world = above_pick;
  std::vector<DeviceInput> samples;
  double t = 0.0;
  Vec3 flange = above_pick;
  double width = s.open_width_m;
  samples.push_back(sample(t, flange, width));
  for (const Waypoint& w : plan) {
    const int n = std::max(1, static_cast<int>(std::ceil(w.duration_s / s.sample_period_s)));
    for (int k = 1; k <= n; ++k) {
      const double u = static_cast<double>(k) / n;
      const double e = minimum_jerk(u);
      Vec3 p = flange + (w.flange_world - flange) * e;
      if (w.circle) {
        // Once round the ball at the hover height, easing in and out of the circle.
        const double a = 2.0 * std::numbers::pi * e;
        const double radius = s.explore_radius_m * std::sin(std::numbers::pi * u);
        p = w.flange_world + Vec3(radius * std::sin(a), radius * (1.0 - std::cos(a)), 0.0) * 0.5;
      }
      samples.push_back(sample(t + u * w.duration_s, p, width + (w.width_m - width) * e));
    }
    out.phases.push_back({w.phase, t, t + w.duration_s});
    t += w.duration_s;
    flange = w.flange_world;
    width = w.width_m;
  }
  out.trajectory = make_trajectory(std::move(samples), 2, 3, where);
  return out;
}

}  // namespace hapsim
