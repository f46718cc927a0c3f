// The viewer's camera: it orbits a target point, Z up (the scenes are Z up). The mouse helpers are
// pure math on pixel deltas so the GUI, the tests and scripted screenshots share them.
// Pixel coordinates run x right, y DOWN from the top-left corner of the viewport (image order,
// as read_rgba() and PNG files store rows); pixel (i, j) covers [i, i+1)×[j, j+1).
#pragma once

#include "hapsim/core/types.h"

namespace hapsim {

/// A ray in the world frame; `direction_world` is unit length.
struct Ray3 {
  Vec3 origin_world = Vec3::Zero();
  Vec3 direction_world = Vec3::UnitX();
};

class OrbitCamera {
 public:
  /// The point looked at and orbited, world frame, metres.
  Vec3 target_world = Vec3::Zero();
  /// Azimuth of the eye around the target, from +X towards +Y, radians.
  double yaw_rad = 0.0;
  /// Elevation of the eye above the target's horizontal plane, radians; kept inside ±kMaxPitch.
  double pitch_rad = 0.5;
  /// Eye-to-target distance, metres.
  double distance_m = 1.0;
  /// Vertical field of view, radians.
  double fov_y_rad = 0.7;

  /// Pitch stays short of ±90° so "Z up" never lines up with the view direction.
  static constexpr double kMaxPitch = 1.55;
  static constexpr double kMinDistance = 1e-4;
  static constexpr double kMaxDistance = 1e4;

  /// The camera whose eye is at `eye_world` looking at `target_world` with vertical field of view
  /// `fov_y_rad` (a view straight up or down is tilted to kMaxPitch).
  [[nodiscard]] static OrbitCamera looking_at(const Vec3& eye_world, const Vec3& target_world,
                                              double fov_y_rad);

  [[nodiscard]] Vec3 eye_world() const;
  /// Camera frame axes in the world: right, up (screen) and forward (towards the target).
  [[nodiscard]] Vec3 right_world() const;
  [[nodiscard]] Vec3 up_world() const;
  [[nodiscard]] Vec3 forward_world() const;

  /// Near/far clip distances follow the orbit distance (ratio 1e4: enough depth precision at
  /// 24 bits, and the floor stays visible far behind the target).
  [[nodiscard]] double near_m() const { return distance_m * 1e-2; }
  [[nodiscard]] double far_m() const { return distance_m * 1e2; }

  /// Camera-from-world (OpenGL convention: camera looks down its −z, y up).
  [[nodiscard]] Eigen::Matrix4d view_matrix() const;
  /// OpenGL clip-from-camera perspective for a viewport of width/height `aspect`.
  [[nodiscard]] Eigen::Matrix4d projection(double aspect) const;

  /// Orbit: dragging right turns the scene right (the eye moves left), dragging down tilts the
  /// eye up. `rad_per_px` sets the sensitivity.
  void rotate(double dx_px, double dy_px, double rad_per_px = 0.005);
  /// Moves the target in the view plane so a point at the target's depth stays under the cursor
  /// (it moves by exactly (dx, dy) pixels on screen).
  void pan(double dx_px, double dy_px, int viewport_height_px);
  /// Multiplies the distance by factor_per_step^(−wheel_steps): positive steps zoom in.
  void zoom(double wheel_steps, double factor_per_step = 1.1);
  /// Looks at the centre of `bounds_world` from the current direction, close enough that the whole
  /// box (its bounding sphere) fits a viewport of `aspect`, with `margin` (≥ 1) to spare.
  void frame(const Box3& bounds_world, double aspect = 1.0, double margin = 1.1);

  /// World point → (x_px, y_px, depth) with depth the window depth in [0, 1] (0 at the near plane).
  /// Points behind the eye return infinite coordinates.
  [[nodiscard]] Vec3 project(const Vec3& p_world, int width_px, int height_px) const;
  /// Inverse of project(): (x_px, y_px, depth) → world point.
  [[nodiscard]] Vec3 unproject(const Vec3& pixel_depth, int width_px, int height_px) const;
  /// The ray from the eye through a pixel position (use +0.5 for a pixel's centre).
  [[nodiscard]] Ray3 ray_through(double x_px, double y_px, int width_px, int height_px) const;
};

}  // namespace hapsim
