#include "hapsim/ui/mouse_probe.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hapsim {

MouseProbe::MouseProbe(const Vec3& start_world, MouseProbeOptions options)
    : options_(std::move(options)), p_world_(start_world) {
  place(start_world);
}

void MouseProbe::place(const Vec3& p_world) {
  if (!p_world.allFinite()) {
    return;
  }
  p_world_ =
      p_world.cwiseMax(options_.workspace_world.min()).cwiseMin(options_.workspace_world.max());
}

void MouseProbe::drag(double dx_px, double dy_px, const OrbitCamera& camera, int height_px) {
  if (height_px <= 0 || !std::isfinite(dx_px) || !std::isfinite(dy_px)) {
    return;
  }
  // Metres per pixel at the probe's depth: the view's height there is 2·d·tan(fov/2).
  const double depth_m =
      std::max((p_world_ - camera.eye_world()).dot(camera.forward_world()), camera.near_m());
  const double m_per_px =
      2.0 * depth_m * std::tan(0.5 * camera.fov_y_rad) / static_cast<double>(height_px);
  place(p_world_ + m_per_px * (dx_px * camera.right_world() - dy_px * camera.up_world()));
}

void MouseProbe::wheel(double steps, const OrbitCamera& camera) {
  if (!std::isfinite(steps)) {
    return;
  }
  place(p_world_ + steps * options_.depth_step_m * camera.forward_world());
}

void MouseProbe::update_fingers(const std::array<bool, kMaxFingers>& held, double dt_s) {
  const double step = options_.finger_rate_rad_per_s * std::clamp(dt_s, 0.0, 0.1);
  for (std::size_t f = 0; f < held.size(); ++f) {
    finger_rad_[f] =
        std::clamp(finger_rad_[f] + (held[f] ? step : -step), 0.0, options_.finger_max_rad);
  }
}

DeviceInput MouseProbe::input() const {
  DeviceInput in;
  in.p_world = p_world_;
  in.finger_count = kMaxFingers;
  in.finger_rad = finger_rad_;
  // A glove's joints per finger: MCP abduction, MCP flexion, PIP (the hand model couples DIP).
  in.joint_count = 3 * kMaxFingers;
  for (std::size_t f = 0; f < kMaxFingers; ++f) {
    in.joint_rad[3 * f + 1] = 0.6 * finger_rad_[f];
    in.joint_rad[3 * f + 2] = finger_rad_[f];
  }
  in.buttons = grasp_closed_ ? 1U : 0U;
  return in;
}

}  // namespace hapsim
