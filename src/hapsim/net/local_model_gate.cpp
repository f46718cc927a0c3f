#include "hapsim/net/local_model_gate.h"

#include "hapsim/net/field_checks.h"
#include "hapsim/net/local_model_codec.h"

#include <algorithm>
#include <cmath>

namespace hapsim::net {

LocalModelGate::LocalModelGate(std::uint16_t device_id, std::uint64_t scene_hash, int finger_count,
                               LocalModelLimits limits) noexcept
    : device_id_(device_id),
      scene_hash_(scene_hash),
      finger_count_(std::clamp(finger_count, 1, kMaxFingers)),
      limits_(limits) {}

namespace {

// A profile is a conservative spring along the normal: depths strictly increasing, pushes never
// falling (a falling push would give energy back as the device goes in), all within the limits.
bool profile_ok(const hapsim_msg_LocalModel& m, const LocalModelLimits& limits) noexcept {
  for (int i = 0; i < m.profile_count; ++i) {
    if (std::abs(m.profile_depth_m[i]) > limits.max_validity_radius_m ||
        std::abs(m.profile_push_n[i]) > limits.max_force_n) {
      return false;
    }
    if (i > 0 && !(m.profile_depth_m[i] > m.profile_depth_m[i - 1] &&
                   m.profile_push_n[i] >= m.profile_push_n[i - 1])) {
      return false;
    }
  }
  return true;
}

}  // namespace

std::uint64_t LocalModelGate::rejected() const noexcept {
  std::uint64_t sum = 0;
  for (std::size_t i = 1; i < kSampleVerdicts; ++i) {
    sum += counts_[i];
  }
  return sum;
}

SampleVerdict LocalModelGate::check(const hapsim_msg_LocalModel& m,
                                    std::uint64_t device_sequence_now) const noexcept {
  if (m.finger >= finger_count_ || !std::isfinite(m.sim_time_s) || !all_finite(m.x0_m) ||
      !all_finite(m.v0_m_per_s) || !all_finite(m.f0_n) || !all_finite(m.stiffness_n_per_m) ||
      !all_finite(m.damping_n_s_per_m) || !all_finite(m.normal) ||
      !std::isfinite(m.validity_radius_m) || !std::isfinite(m.max_normal_force_n) ||
      m.profile_count > LocalContactModel::kMaxProfilePoints || m.profile_count == 1 ||
      !all_finite(m.profile_depth_m) || !all_finite(m.profile_push_n)) {
    return SampleVerdict::kMalformed;
  }
  if (m.device_id != device_id_) {
    return SampleVerdict::kOtherDevice;
  }
  if (m.scene_hash != scene_hash_) {
    return SampleVerdict::kOtherScene;
  }
  const bool diagonal_ok = m.stiffness_n_per_m[0] >= 0.0 && m.stiffness_n_per_m[4] >= 0.0 &&
                           m.stiffness_n_per_m[8] >= 0.0 && m.damping_n_s_per_m[0] >= 0.0 &&
                           m.damping_n_s_per_m[4] >= 0.0 && m.damping_n_s_per_m[8] >= 0.0;
  const double normal_sq =
      m.normal[0] * m.normal[0] + m.normal[1] * m.normal[1] + m.normal[2] * m.normal[2];
  // A contact's normal is a unit vector (free space sends none); a model cannot answer a device
  // state the device has not sent yet.
  const bool normal_ok = normal_sq == 0.0 || std::abs(normal_sq - 1.0) < 1e-6;
  if (!within(m.f0_n, limits_.max_force_n) ||
      !within(m.stiffness_n_per_m, limits_.max_stiffness_n_per_m) ||
      !within(m.damping_n_s_per_m, limits_.max_damping_n_s_per_m) ||
      !within(m.x0_m, limits_.max_position_m) || !within(m.v0_m_per_s, limits_.max_speed_m_per_s) ||
      !(m.validity_radius_m >= 0.0 && m.validity_radius_m <= limits_.max_validity_radius_m) ||
      !diagonal_ok || !normal_ok || m.device_sequence > device_sequence_now ||
      !(m.max_normal_force_n == -1.0 ||
        (m.max_normal_force_n >= 0.0 && m.max_normal_force_n <= limits_.max_force_n)) ||
      !profile_ok(m, limits_)) {
    return SampleVerdict::kOutOfRange;
  }
  const auto finger = static_cast<std::size_t>(m.finger);
  if (has_newest_[finger] && m.model_sequence <= newest_sequence_[finger]) {
    return SampleVerdict::kOutOfOrder;
  }
  // Sequence 0 answers no device state (the simulation's own script): no age to tell; the
  // device host counts it as not its own and renders nothing of it.
  if (m.device_sequence != 0 && device_sequence_now - m.device_sequence > limits_.max_age_cycles) {
    return SampleVerdict::kStale;
  }
  return SampleVerdict::kAccepted;
}

// haptic path
SampleVerdict LocalModelGate::admit(const hapsim_msg_LocalModel& message,
                                    std::uint64_t device_sequence_now,
                                    LocalContactModel& out) noexcept {
  const SampleVerdict verdict = check(message, device_sequence_now);
  ++counts_[static_cast<std::size_t>(verdict)];
  if (verdict == SampleVerdict::kAccepted) {
    const auto finger = static_cast<std::size_t>(message.finger);
    newest_sequence_[finger] = message.model_sequence;
    has_newest_[finger] = true;
    out = decode_local_model(message);
  }
  return verdict;
}

}  // namespace hapsim::net
