// A local contact model to and from its DDS message (force/local_contact_model.h,
// net/idl/hapsim_messages.idl). Plain copies: what a received message may be trusted with is
// net/local_model_gate.h's decision.
#pragma once

#include "hapsim/force/local_contact_model.h"
#include "hapsim_messages.h"

#include <cstdint>

namespace hapsim::net {

/// Which contact a model is for: the device and its finger (0 for a single-point tool).
struct ContactKey {
  std::uint16_t device_id = 0;
  std::uint16_t finger = 0;
};

/// haptic path
[[nodiscard]] hapsim_msg_LocalModel encode_local_model(const LocalContactModel& model,
                                                       ContactKey key,
                                                       std::uint64_t scene_hash) noexcept;
/// haptic path
[[nodiscard]] LocalContactModel decode_local_model(const hapsim_msg_LocalModel& message) noexcept;

}  // namespace hapsim::net
