// The viewer's mouse-and-keyboard haptic device (architecture.md#devices, issue 5): a probe the
// user moves with the mouse — dragging moves it in the view plane so it stays under the cursor, the
// wheel moves it towards or away from the viewer — and fingers curled with keys (a glove scene's
// hand) or a grasp opened and closed (teleoperation). Pure math on pixel deltas and the camera, so
// tests drive it exactly as the GUI does; the result is a DeviceInput for InteractiveDevice.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/render/camera.h"

#include <array>

namespace hapsim {

struct MouseProbeOptions {
  /// Probe travel per wheel step along the view direction, metres.
  double depth_step_m = 0.002;
  /// Finger curl speed while its key is held, rad/s, and the most it curls.
  double finger_rate_rad_per_s = 2.0;
  double finger_max_rad = 1.4;
  /// The probe never leaves this box (world frame): a runaway drag cannot fling it far away.
  Box3 workspace_world = Box3(Vec3::Constant(-1.0), Vec3::Constant(1.0));
};

class MouseProbe {
 public:
  explicit MouseProbe(const Vec3& start_world, MouseProbeOptions options = {});

  /// Moves the probe by a cursor motion of (dx, dy) pixels in a viewport of `height_px`, so its
  /// image follows the cursor (x right, y down).
  void drag(double dx_px, double dy_px, const OrbitCamera& camera, int height_px);
  /// Moves the probe along the view direction: positive steps push it away from the viewer
  /// (into the scene).
  void wheel(double steps, const OrbitCamera& camera);
  /// Curls (held) or releases finger `finger` (0..4) over `dt_s` seconds.
  void update_fingers(const std::array<bool, kMaxFingers>& held, double dt_s);
  /// Grasp opening for a gripper (teleoperation): 1 open, 0 closed.
  void set_grasp_closed(bool closed) { grasp_closed_ = closed; }
  void place(const Vec3& p_world);

  [[nodiscard]] const Vec3& p_world() const { return p_world_; }
  [[nodiscard]] const std::array<double, kMaxFingers>& finger_rad() const { return finger_rad_; }
  [[nodiscard]] bool grasp_closed() const { return grasp_closed_; }
  /// The device input: pose, finger flexion (also as glove joints MCP flexion and PIP per
  /// finger, j[3f+1], j[3f+2]), grasp in finger_rad when no finger keys are used.
  [[nodiscard]] DeviceInput input() const;

 private:
  MouseProbeOptions options_;
  Vec3 p_world_;
  std::array<double, kMaxFingers> finger_rad_{};
  bool grasp_closed_ = false;
};

}  // namespace hapsim
