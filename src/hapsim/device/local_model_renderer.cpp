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
  if (std::isnan(m.max_normal_force_n) || m.max_normal_force_n < 0.0) {
    return false;
  }
  for (int i = 0; i < 3; ++i) {
    // A negative diagonal would push the device away from where it is told to stay: energy out.
    if (m.stiffness_n_per_m(i, i) < 0.0 || m.damping_n_s_per_m(i, i) < 0.0) {
      return false;
    }
  }
  // A profile, like K, must not push harder as the device backs out.
  if (m.profile_count < 0 || m.profile_count == 1 ||
      m.profile_count > LocalContactModel::kMaxProfilePoints) {
    return false;
  }
  for (int i = 0; i < m.profile_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!std::isfinite(m.profile_depth_m[k]) || !std::isfinite(m.profile_push_n[k]) ||
        (i > 0 && !(m.profile_depth_m[k] > m.profile_depth_m[k - 1] &&
                    m.profile_push_n[k] >= m.profile_push_n[k - 1]))) {
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
      !finite_non_negative(options_.fade_time_s) ||
      !finite_non_negative(options_.reengage_time_s)) {
    throw Error("local model renderer",
                "blend, stale, fade and re-engagement times must be finite and >= 0");
  }
}

namespace {

// What is left at `now_s` of an offset that decays linearly from `from_s` over `length_s`.
Vec3 decayed(const Vec3& offset_n, double from_s, double length_s, double now_s) noexcept {
  const double alpha = length_s > 0.0 ? std::clamp((now_s - from_s) / length_s, 0.0, 1.0) : 1.0;
  return (1.0 - alpha) * offset_n;
}

}  // namespace

Vec3 LocalModelRenderer::offset(double now_s) const noexcept {
  return decayed(offset_n_, received_s_, options_.blend_time_s, now_s) + reengage_offset(now_s);
}

Vec3 LocalModelRenderer::reengage_offset(double now_s) const noexcept {
  return decayed(reengage_offset_n_, reengage_from_s_, options_.reengage_time_s, now_s);
}

// haptic path
void LocalModelRenderer::receive(const LocalContactModel& model, double now_s) noexcept {
  if (!usable(model) || !std::isfinite(now_s)) {
    ++counts_.models_refused;
    return;
  }
  ++counts_.models_received;
  // Start from what the old model renders now (its offset decayed to now, so a stream of
  // agreeing models lets an offset die out at the blend's rate), or from what was last felt
  // when the old model went stale, or from nothing before any. "Renders" by every rule, as the
  // hand would feel it, not the bare sum: a model that would pull (its damping against a quick
  // step out) is not felt, and blending from its pull left one in the offset, which a free-space
  // model after it rendered (no normal, so no push-only rule); a served rig's pad leaving the
  // knee, its models alternating between contact and free space, stacked those pulls to 11 N.
  const Vec3 x_m = has_rendered_ ? last_x_m_ : model.x0_world_m;
  const Vec3 v_m_per_s = has_rendered_ ? last_v_m_per_s_ : model.v0_world_m_per_s;
  Vec3 start_n = Vec3::Zero();
  const bool stale = has_model_ && freshness(now_s) < 1.0;
  if (has_model_ && has_rendered_) {
    start_n = stale ? last_force_n_ : shaped(x_m, v_m_per_s, now_s, nullptr);
  }
  Vec3 total_offset_n = start_n - local_model_force(model, x_m, v_m_per_s);
  if (!total_offset_n.allFinite()) {
    total_offset_n.setZero();
  }
  if (stale && options_.reengage_time_s > options_.blend_time_s) {
    // The whole step back to the contact ramps in slowly; the models that follow (one a cycle)
    // leave that ramp running and blend only their own differences.
    reengage_offset_n_ = total_offset_n;
    reengage_from_s_ = now_s;
    offset_n_.setZero();
    ++counts_.reengaged;
  } else {
    offset_n_ = total_offset_n - reengage_offset(now_s);
  }
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
  if (!has_model_) {
    return Vec3::Zero();
  }
  if (!x_world_m.allFinite() || !v_world_m_per_s.allFinite() || !std::isfinite(now_s)) {
    ++counts_.nonfinite;
    return Vec3::Zero();
  }
  has_rendered_ = true;
  last_x_m_ = x_world_m;
  last_v_m_per_s_ = v_world_m_per_s;
  last_force_n_ = shaped(x_world_m, v_world_m_per_s, now_s, &counts_);
  return last_force_n_;
}

// haptic path
Vec3 LocalModelRenderer::shaped(const Vec3& x_world_m, const Vec3& v_world_m_per_s, double now_s,
                                LocalModelRenderCounts* counts) const noexcept {
  LocalModelRenderCounts uncounted;
  LocalModelRenderCounts& c = counts != nullptr ? *counts : uncounted;
  if (newest_.valid && (x_world_m - newest_.x0_world_m).norm() > newest_.validity_radius_m) {
    ++c.outside_radius;
    return Vec3::Zero();
  }
  // An invalid (free-space) model renders zero, but for what is left of the blend from the
  // contact before it: letting go is a ramp too.
  Vec3 f = local_model_force(newest_, x_world_m, v_world_m_per_s) + offset(now_s);
  if (!f.allFinite()) {
    ++c.nonfinite;
    return Vec3::Zero();
  }
  if (newest_.valid && f.dot(newest_.normal_world) < 0.0) {
    ++c.pull_zeroed;
    return Vec3::Zero();
  }
  // A saturating contact pushes no harder deeper in: its cap bounds the push along the normal.
  if (newest_.valid && !newest_.normal_world.isZero()) {
    const double push_n = f.dot(newest_.normal_world);
    if (push_n > newest_.max_normal_force_n) {
      ++c.capped;
      f -= (push_n - newest_.max_normal_force_n) * newest_.normal_world;
    }
  }
  const double fresh = freshness(now_s);
  if (fresh < 1.0) {
    ++c.fading;
    f *= fresh;
  }
  const double magnitude = f.norm();
  if (magnitude > options_.max_force_n) {
    ++c.clamped;
    f *= options_.max_force_n / magnitude;
  }
  return f;
}

}  // namespace hapsim
