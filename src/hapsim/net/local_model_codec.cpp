#include "hapsim/net/local_model_codec.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapsim::net {

namespace {

void put(const Vec3& v, double (&out)[3]) noexcept {
  for (int i = 0; i < 3; ++i) {
    out[i] = v[i];
  }
}

void put(const Mat3& m, double (&out)[9]) noexcept {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      out[3 * r + c] = m(r, c);
    }
  }
}

Vec3 vec(const double (&in)[3]) noexcept {
  return {in[0], in[1], in[2]};
}

Mat3 mat(const double (&in)[9]) noexcept {
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      m(r, c) = in[3 * r + c];
    }
  }
  return m;
}

}  // namespace

// haptic path
hapsim_msg_LocalModel encode_local_model(const LocalContactModel& model, ContactKey key,
                                         std::uint64_t scene_hash) noexcept {
  hapsim_msg_LocalModel m{};
  m.device_id = key.device_id;
  m.finger = key.finger;
  m.model_sequence = model.sequence;
  m.device_sequence = model.device_sequence;
  m.scene_hash = scene_hash;
  m.sim_time_s = model.sim_time_s;
  put(model.x0_world_m, m.x0_m);
  put(model.v0_world_m_per_s, m.v0_m_per_s);
  put(model.f0_world_n, m.f0_n);
  put(model.stiffness_n_per_m, m.stiffness_n_per_m);
  put(model.damping_n_s_per_m, m.damping_n_s_per_m);
  put(model.normal_world, m.normal);
  m.validity_radius_m = model.validity_radius_m;
  m.valid = model.valid;
  m.max_normal_force_n = std::isinf(model.max_normal_force_n) ? -1.0 : model.max_normal_force_n;
  const int points = std::clamp(model.profile_count, 0, LocalContactModel::kMaxProfilePoints);
  m.profile_count = static_cast<std::uint16_t>(points);
  for (int i = 0; i < points; ++i) {
    m.profile_depth_m[i] = model.profile_depth_m[static_cast<std::size_t>(i)];
    m.profile_push_n[i] = model.profile_push_n[static_cast<std::size_t>(i)];
  }
  return m;
}

// haptic path
LocalContactModel decode_local_model(const hapsim_msg_LocalModel& m) noexcept {
  LocalContactModel model;
  model.sequence = m.model_sequence;
  model.device_sequence = m.device_sequence;
  model.sim_time_s = m.sim_time_s;
  model.x0_world_m = vec(m.x0_m);
  model.v0_world_m_per_s = vec(m.v0_m_per_s);
  model.f0_world_n = vec(m.f0_n);
  model.stiffness_n_per_m = mat(m.stiffness_n_per_m);
  model.damping_n_s_per_m = mat(m.damping_n_s_per_m);
  model.normal_world = vec(m.normal);
  model.validity_radius_m = m.validity_radius_m;
  model.valid = m.valid;
  model.max_normal_force_n =
      m.max_normal_force_n < 0.0 ? std::numeric_limits<double>::infinity() : m.max_normal_force_n;
  model.profile_count = std::min<int>(m.profile_count, LocalContactModel::kMaxProfilePoints);
  for (int i = 0; i < model.profile_count; ++i) {
    model.profile_depth_m[static_cast<std::size_t>(i)] = m.profile_depth_m[i];
    model.profile_push_n[static_cast<std::size_t>(i)] = m.profile_push_n[i];
  }
  return model;
}

}  // namespace hapsim::net
