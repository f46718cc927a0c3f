// Which received device states the simulation may step with (the simulation host's side of
// net/local_model_gate.h): finite, believable, this scene's, this device's, newer than the last.
#pragma once

#include "hapsim/net/device_state_codec.h"
#include "hapsim/net/sample_verdict.h"

#include <cstdint>

namespace hapsim::net {

struct DeviceStateLimits {
  double max_position_m = 100.0;
  double max_speed_m_per_s = 100.0;
  double max_force_n = 1000.0;
};

class DeviceStateGate {
 public:
  DeviceStateGate(std::uint16_t device_id, std::uint64_t scene_hash,
                  DeviceStateLimits limits = {}) noexcept
      : device_id_(device_id), scene_hash_(scene_hash), limits_(limits) {}

  /// The verdict on `message`, counted; on kAccepted `out` holds the decoded state (its
  /// orientation normalised). haptic path
  SampleVerdict admit(const hapsim_msg_DeviceState& message, DeviceStateSample& out) noexcept;

  [[nodiscard]] std::uint64_t count(SampleVerdict verdict) const noexcept {
    return counts_[static_cast<std::size_t>(verdict)];
  }
  [[nodiscard]] const VerdictCounts& counts() const noexcept { return counts_; }

  /// Accept the next state whatever its sequence: the device host went silent, and one that
  /// comes back (or a restarted one) numbers its states afresh. haptic path
  void forget_order() noexcept { has_newest_ = false; }

 private:
  [[nodiscard]] SampleVerdict check(const hapsim_msg_DeviceState& m) const noexcept;

  std::uint16_t device_id_;
  std::uint64_t scene_hash_;
  DeviceStateLimits limits_;
  std::uint64_t newest_sequence_ = 0;
  bool has_newest_ = false;
  VerdictCounts counts_{};
};

}  // namespace hapsim::net
