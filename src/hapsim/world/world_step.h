// One deterministic world step: a plain function of the read-only model, the per-step state and
// this cycle's device input (ARCHITECTURE: step(model, state, input, dt)). The real-time loop
// only calls it on time; tests, replays and benchmarks call it directly, so they are exact and
// need no clock. The stages it runs, in order, are in world_stages.h.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/force/contact_material.h"
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_state.h"

#include <cstdint>

namespace hapsim {

/// haptic path. Advances `state` by `dt_s` (a non-finite or non-positive dt steps by 0). A
/// non-finite or unhealthy input holds the tools where they were and outputs zero force (never
/// NaN). Precondition: `state` was built for `model`.
const StepResult& step(const WorldModel& model, WorldState& state, const DeviceInput& input,
                       double dt_s) noexcept;

/// The material a step uses: `contact` (as edited) with its stiffness clamped to the model's
/// maximum and its damping raised to the passivity floor factor·k·dt.
[[nodiscard]] ContactMaterial effective_material(const WorldModel& model,
                                                 const ContactMaterial& contact,
                                                 double dt_s) noexcept;

}  // namespace hapsim
