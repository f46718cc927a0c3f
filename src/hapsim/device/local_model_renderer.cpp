#include "hapsim/device/local_model_renderer.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hapsim {

namespace {

bool finite_non_negative(double value) {
  return std::isfinite(value) && value >= 0.0;
}

bool usable(const LocalContactModel& m) noexcept {
  if (!m.x0_world_m.allFinite() || !m.v0_world_m_per_s.allFinite() || !m.f0_world_n.allFinite() ||
      !m.stiffness_n_per_m.allFinite() || !m.damping_n_s_per_m.allFinite() ||
      !m.normal_world.allFinite() || !finite_non_negative(m.validity_radius_m)) {
    return false;
  }
  for (int i = 0; i < 3; ++i) {
    // A negative diagonal would push the device away from where it is told to stay: energy out.
    if (m.stiffness_n_per_m(i, i) < 0.0 || m.damping_n_s_per_m(i, i) < 0.0) {
      return false;
    }
  }
  return true;
}

}  // namespace

LocalModelRenderer::LocalModelRenderer(LocalModelRenderOptions options) : options_(options) {
  if (!(std::isfinite(options_.max_force_n) && options_.max_force_n > 0.0)) {
    throw Error("local model renderer",
                "max_force_n must be finite and > 0, got " + std::to_string(options_.max_force_n));
  }
  if (!finite_non_negative(options_.blend_time_s) || !finite_non_negative(options_.stale_after_s) ||
      !finite_non_negative(options_.fade_time_s)) {
    throw Error("local model renderer", "blend, stale and fade times must be finite and >= 0");
  }
}

LocalModelRenderer::Affine LocalModelRenderer::affine_of(const LocalContactModel& m) noexcept {
  if (!m.valid) {
    return {};
  }
  return {
      m.f0_world_n + m.stiffness_n_per_m * m.x0_world_m + m.damping_n_s_per_m * m.v0_world_m_per_s,
      m.stiffness_n_per_m, m.damping_n_s_per_m};
}

LocalModelRenderer::Affine LocalModelRenderer::blended(double now_s) const noexcept {
  const double since_s = now_s - received_s_;
  const double alpha =
      options_.blend_time_s > 0.0 ? std::clamp(since_s / options_.blend_time_s, 0.0, 1.0) : 1.0;
  if (alpha >= 1.0) {
    return to_;
  }
  return {(1.0 - alpha) * from_.c_n + alpha * to_.c_n,
          (1.0 - alpha) * from_.k_n_per_m + alpha * to_.k_n_per_m,
          (1.0 - alpha) * from_.b_n_s_per_m + alpha * to_.b_n_s_per_m};
}

// haptic path
void LocalModelRenderer::receive(const LocalContactModel& model, double now_s) noexcept {
  if (!usable(model) || !std::isfinite(now_s)) {
    ++counts_.models_refused;
    return;
  }
  ++counts_.models_received;
  // Blend from what is felt now; a stale model has faded, so start from nothing.
  from_ = has_model_ && freshness(now_s) >= 1.0 ? blended(now_s) : Affine{};
  to_ = affine_of(model);
  newest_ = model;
  received_s_ = now_s;
  has_model_ = true;
}

double LocalModelRenderer::freshness(double now_s) const noexcept {
  if (!has_model_) {
    return 0.0;
  }
  const double age_s = now_s - received_s_;
  if (!(age_s > options_.stale_after_s)) {
    return 1.0;
  }
  if (!(options_.fade_time_s > 0.0)) {
    return 0.0;
  }
  return std::clamp(1.0 - (age_s - options_.stale_after_s) / options_.fade_time_s, 0.0, 1.0);
}

// haptic path
Vec3 LocalModelRenderer::render(const Vec3& x_world_m, const Vec3& v_world_m_per_s,
                                double now_s) noexcept {
  if (!has_model_ || !newest_.valid) {
    return Vec3::Zero();
  }
  if (!x_world_m.allFinite() || !v_world_m_per_s.allFinite() || !std::isfinite(now_s)) {
    ++counts_.nonfinite;
    return Vec3::Zero();
  }
  if ((x_world_m - newest_.x0_world_m).norm() > newest_.validity_radius_m) {
    ++counts_.outside_radius;
    return Vec3::Zero();
  }
  const Affine a = blended(now_s);
  Vec3 f = a.c_n - a.k_n_per_m * x_world_m - a.b_n_s_per_m * v_world_m_per_s;
  if (!f.allFinite()) {
    ++counts_.nonfinite;
    return Vec3::Zero();
  }
  if (f.dot(newest_.normal_world) < 0.0) {
    ++counts_.pull_zeroed;
    return Vec3::Zero();
  }
  const double fresh = freshness(now_s);
  if (fresh < 1.0) {
    ++counts_.fading;
    f *= fresh;
  }
  const double magnitude = f.norm();
  if (magnitude > options_.max_force_n) {
    ++counts_.clamped;
    f *= options_.max_force_n / magnitude;
  }
  return f;
}

}  // namespace hapsim
