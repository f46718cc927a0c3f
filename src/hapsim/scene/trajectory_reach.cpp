#include "hapsim/scene/trajectory_reach.h"

#include "hapsim/kinematics/hand_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace hapsim {

TrajectoryReach trajectory_reach(const World& world, Device& device, double duration_s,
                                 double dt_s) {
  TrajectoryReach reach;
  const WorldDescription& d = world.description();
  const std::vector<SegmentModel>& segments = world.model().segments();
  if (segments.empty() || d.tools.empty() || !(dt_s > 0.0) || !std::isfinite(duration_s) ||
      std::any_of(d.bodies.begin(), d.bodies.end(),
                  [](const BodyDescription& b) { return b.kind == BodyKind::kDynamic; })) {
    return reach;
  }
  const double length_s = std::max(duration_s, 0.0);
  const double step_s = std::max(dt_s, length_s / static_cast<double>(kReachMaxSamples - 1));
  const auto samples = static_cast<std::size_t>(std::floor(length_s / step_s + 1e-9)) + 1;
  const HandModel* hand = world.model().hand();
  reach.gap_m = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i <= samples; ++i) {
    // The last read is at the end itself, whatever the spacing.
    const double t = i < samples ? static_cast<double>(i) * step_s : length_s;
    const DeviceInput in = device.read(t);
    if (!in.healthy || !in.p_world.allFinite() || !in.q_world.coeffs().allFinite() ||
        !(in.q_world.squaredNorm() > 0.5)) {
      continue;
    }
    const Quat q = in.q_world.normalized();
    std::array<Vec3, kHandFingers> tips{};
    if (hand != nullptr) {
      Iso3 X_world_hand = Iso3::Identity();
      X_world_hand.linear() = q.toRotationMatrix();
      X_world_hand.translation() = in.p_world;
      tips = hand->fingertips_world(glove_reading(
          X_world_hand, {in.joint_rad.data(), static_cast<std::size_t>(std::clamp(
                                                  in.joint_count, 0, kMaxDeviceJoints))}));
    }
    for (const ToolDescription& tool : d.tools) {
      if (hand != nullptr && (tool.finger < 0 || tool.finger >= kHandFingers)) {
        continue;
      }
      const Vec3 p_world = hand != nullptr ? tips[static_cast<std::size_t>(tool.finger)]
                                           : Vec3(in.p_world + q * tool.offset_device);
      if (!p_world.allFinite()) {
        continue;
      }
      for (const SegmentModel& seg : segments) {
        const Vec3 p_body = seg.X_body_world * p_world;
        const Vec3 nearest =
            p_body.cwiseMax(seg.rest_bounds_body.min()).cwiseMin(seg.rest_bounds_body.max());
        const double gap = std::max(0.0, (p_body - nearest).norm() - tool.radius_m);
        if (gap < reach.gap_m) {
          reach.gap_m = gap;
          reach.body = d.bodies[seg.body].name;
          reach.tool = tool.name;
          reach.time_s = t;
        }
      }
    }
    if (reach.gap_m == 0.0) {
      break;  // within reach: nothing more to learn
    }
  }
  reach.checked = std::isfinite(reach.gap_m);
  if (!reach.checked) {
    reach.gap_m = 0.0;
  }
  return reach;
}

}  // namespace hapsim
