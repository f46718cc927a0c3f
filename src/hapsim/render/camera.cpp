#include "hapsim/render/camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hapsim {

OrbitCamera OrbitCamera::looking_at(const Vec3& eye_world, const Vec3& target_world,
                                    double fov_y_rad) {
  OrbitCamera c;
  const Vec3 d = eye_world - target_world;
  c.target_world = target_world;
  c.distance_m = std::clamp(d.norm(), kMinDistance, kMaxDistance);
  c.yaw_rad = std::atan2(d.y(), d.x());
  c.pitch_rad = std::clamp(std::asin(std::clamp(d.z() / std::max(d.norm(), 1e-300), -1.0, 1.0)),
                           -kMaxPitch, kMaxPitch);
  c.fov_y_rad = fov_y_rad;
  return c;
}

Vec3 OrbitCamera::eye_world() const {
  return target_world - distance_m * forward_world();
}

Vec3 OrbitCamera::forward_world() const {
  return -Vec3(std::cos(pitch_rad) * std::cos(yaw_rad), std::cos(pitch_rad) * std::sin(yaw_rad),
               std::sin(pitch_rad));
}

// forward × Z, normalised; horizontal because the eye never looks straight up or down.
Vec3 OrbitCamera::right_world() const {
  return Vec3(-std::sin(yaw_rad), std::cos(yaw_rad), 0.0);
}

Vec3 OrbitCamera::up_world() const {
  return right_world().cross(forward_world());
}

Eigen::Matrix4d OrbitCamera::view_matrix() const {
  Eigen::Matrix3d R_CW;
  R_CW.row(0) = right_world().transpose();
  R_CW.row(1) = up_world().transpose();
  R_CW.row(2) = -forward_world().transpose();
  Eigen::Matrix4d X_camera_world = Eigen::Matrix4d::Identity();
  X_camera_world.topLeftCorner<3, 3>() = R_CW;
  X_camera_world.topRightCorner<3, 1>() = -R_CW * eye_world();
  return X_camera_world;
}

Eigen::Matrix4d OrbitCamera::projection(double aspect) const {
  const double f = 1.0 / std::tan(0.5 * fov_y_rad);
  const double n = near_m();
  const double far = far_m();
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = f / aspect;
  P(1, 1) = f;
  P(2, 2) = (far + n) / (n - far);
  P(2, 3) = 2.0 * far * n / (n - far);
  P(3, 2) = -1.0;
  return P;
}

void OrbitCamera::rotate(double dx_px, double dy_px, double rad_per_px) {
  // d(eye)/d(yaw) points along `right`, so the eye moves left for a drag to the right.
  yaw_rad = std::remainder(yaw_rad - dx_px * rad_per_px, 2.0 * std::numbers::pi);
  pitch_rad = std::clamp(pitch_rad + dy_px * rad_per_px, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(double dx_px, double dy_px, int viewport_height_px) {
  // Size of one pixel in the plane through the target, facing the camera.
  const double m_per_px =
      2.0 * distance_m * std::tan(0.5 * fov_y_rad) / std::max(viewport_height_px, 1);
  target_world += m_per_px * (-dx_px * right_world() + dy_px * up_world());
}

void OrbitCamera::zoom(double wheel_steps, double factor_per_step) {
  distance_m =
      std::clamp(distance_m * std::pow(factor_per_step, -wheel_steps), kMinDistance, kMaxDistance);
}

void OrbitCamera::frame(const Box3& bounds_world, double aspect, double margin) {
  if (bounds_world.isEmpty()) {
    return;
  }
  target_world = bounds_world.center();
  const double radius = 0.5 * bounds_world.diagonal().norm();
  if (radius <= 0.0) {
    return;
  }
  // The narrower of the two half-angles decides; a sphere inside that cone fits the viewport.
  const double half_y = 0.5 * fov_y_rad;
  const double half_x = std::atan(aspect * std::tan(half_y));
  const double half = std::min(half_x, half_y);
  distance_m =
      std::clamp(std::max(margin, 1.0) * radius / std::sin(half), kMinDistance, kMaxDistance);
}

Vec3 OrbitCamera::project(const Vec3& p_world, int width_px, int height_px) const {
  const double aspect = static_cast<double>(width_px) / height_px;
  const Eigen::Vector4d clip = projection(aspect) * view_matrix() * p_world.homogeneous();
  if (clip.w() <= 0.0) {
    return Vec3::Constant(kInf);
  }
  const Vec3 ndc = clip.head<3>() / clip.w();
  return Vec3(0.5 * (ndc.x() + 1.0) * width_px, 0.5 * (1.0 - ndc.y()) * height_px,
              0.5 * (ndc.z() + 1.0));
}

Vec3 OrbitCamera::unproject(const Vec3& pixel_depth, int width_px, int height_px) const {
  const double aspect = static_cast<double>(width_px) / height_px;
  const Eigen::Vector4d ndc(2.0 * pixel_depth.x() / width_px - 1.0,
                            1.0 - 2.0 * pixel_depth.y() / height_px, 2.0 * pixel_depth.z() - 1.0,
                            1.0);
  const Eigen::Vector4d p = (projection(aspect) * view_matrix()).inverse() * ndc;
  return p.head<3>() / p.w();
}

Ray3 OrbitCamera::ray_through(double x_px, double y_px, int width_px, int height_px) const {
  Ray3 ray;
  ray.origin_world = eye_world();
  ray.direction_world =
      (unproject(Vec3(x_px, y_px, 0.5), width_px, height_px) - ray.origin_world).normalized();
  return ray;
}

}  // namespace hapsim
