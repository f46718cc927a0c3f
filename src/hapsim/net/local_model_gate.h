// Which received local-model samples a device may apply (issue 12: "samples that are malformed,
// out of range, from another scene or out of order are dropped and counted, never applied").
// Every sample gets one verdict and every verdict is counted, so a hostile or broken peer shows
// up in the device's health report instead of in the user's hand.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/force/local_contact_model.h"
#include "hapsim/net/sample_verdict.h"
#include "hapsim_messages.h"

#include <array>
#include <cstddef>
#include <cstdint>

namespace hapsim::net {

/// Bounds of a believable model (a wild but finite sample is refused, not clamped: it says the
/// sender is wrong, and its f0 or K would be applied at full weight by the renderer).
struct LocalModelLimits {
  double max_force_n = 1000.0;
  double max_stiffness_n_per_m = 1e6;
  double max_damping_n_s_per_m = 1e4;
  double max_position_m = 100.0;
  double max_speed_m_per_s = 100.0;
  double max_validity_radius_m = 1.0;
  /// A model answering a device state more than this many device cycles old is stale (the
  /// device counts its own cycles: no clock is compared across hosts).
  std::uint64_t max_age_cycles = 500;
};

class LocalModelGate {
 public:
  LocalModelGate(std::uint16_t device_id, std::uint64_t scene_hash, int finger_count,
                 LocalModelLimits limits = {}) noexcept;

  /// The verdict on `message`, counted; on kAccepted `out` holds the decoded model and the key's
  /// newest sequence advances. `device_sequence_now` is the device's own newest state sequence.
  /// haptic path
  SampleVerdict admit(const hapsim_msg_LocalModel& message, std::uint64_t device_sequence_now,
                      LocalContactModel& out) noexcept;

  [[nodiscard]] std::uint64_t count(SampleVerdict verdict) const noexcept {
    return counts_[static_cast<std::size_t>(verdict)];
  }
  [[nodiscard]] std::uint64_t rejected() const noexcept;

 private:
  [[nodiscard]] SampleVerdict check(const hapsim_msg_LocalModel& m,
                                    std::uint64_t device_sequence_now) const noexcept;

  std::uint16_t device_id_;
  std::uint64_t scene_hash_;
  int finger_count_;
  LocalModelLimits limits_;
  std::array<std::uint64_t, kMaxFingers> newest_sequence_{};
  std::array<bool, kMaxFingers> has_newest_{};
  std::array<std::uint64_t, kSampleVerdicts> counts_{};
};

}  // namespace hapsim::net
