#include "hapsim/net/device_state_gate.h"

#include "hapsim/net/field_checks.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace hapsim::net {

SampleVerdict DeviceStateGate::check(const hapsim_msg_DeviceState& m) const noexcept {
  if (!std::isfinite(m.device_time_s) || !all_finite(m.p_m) || !all_finite(m.q_wxyz) ||
      !all_finite(m.v_m_per_s) || !all_finite(m.finger_rad) || !all_finite(m.rendered_force_n) ||
      !all_finite(m.rendered_finger_force_n) || m.finger_count > kMaxFingers ||
      !all_finite(m.joint_rad) || m.joint_count > kMaxDeviceJoints) {
    return SampleVerdict::kMalformed;
  }
  if (m.device_id != device_id_) {
    return SampleVerdict::kOtherDevice;
  }
  if (m.scene_hash != scene_hash_) {
    return SampleVerdict::kOtherScene;
  }
  const double q_sq = m.q_wxyz[0] * m.q_wxyz[0] + m.q_wxyz[1] * m.q_wxyz[1] +
                      m.q_wxyz[2] * m.q_wxyz[2] + m.q_wxyz[3] * m.q_wxyz[3];
  // An orientation is a unit quaternion; a little drift is normalised, a wrong one refused.
  if (std::abs(q_sq - 1.0) > 1e-3 || !within(m.p_m, limits_.max_position_m) ||
      !within(m.v_m_per_s, limits_.max_speed_m_per_s) ||
      !within(m.rendered_force_n, limits_.max_force_n) ||
      !within(m.rendered_finger_force_n, limits_.max_force_n)) {
    return SampleVerdict::kOutOfRange;
  }
  if (has_newest_ && m.state_sequence <= newest_sequence_) {
    return SampleVerdict::kOutOfOrder;
  }
  return SampleVerdict::kAccepted;
}

// haptic path
SampleVerdict DeviceStateGate::admit(const hapsim_msg_DeviceState& message,
                                     DeviceStateSample& out) noexcept {
  const SampleVerdict verdict = check(message);
  ++counts_[static_cast<std::size_t>(verdict)];
  if (verdict == SampleVerdict::kAccepted) {
    newest_sequence_ = message.state_sequence;
    has_newest_ = true;
    out = decode_device_state(message);
    out.input.q_world.normalize();
  }
  return verdict;
}

}  // namespace hapsim::net
