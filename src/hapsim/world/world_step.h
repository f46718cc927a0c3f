// One deterministic world step: a plain function of the read-only model, the per-step state and
// this cycle's device input (ARCHITECTURE: step(model, state, input, dt)). The real-time loop
// only calls it on time; tests, replays and benchmarks call it directly, so they are exact and
// need no clock. The stages it runs, in order, are in world_stages.h.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/force/contact_material.h"
#include "hapsim/force/local_contact_model.h"
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
/// maximum and its damping raised to the passivity floor (world/passivity_floor.h).
[[nodiscard]] ContactMaterial effective_material(const WorldModel& model,
                                                 const ContactMaterial& contact,
                                                 double dt_s) noexcept;

/// The normal damping of a FEM body's contact rendered from `fem_model` (its normal and series
/// stiffness k): the material's own (as edited), raised to the passivity floor factor·k·dt of the
/// stiffness the contact renders (the contact spring in series with the tissue, not the contact
/// spring alone: that floor was ten times the series one on a 20 kPa block, a drag of 0.15 N at
/// 50 mm/s), and to the floor the FEM side asks for in the model's damping (its tissue's motion
/// sampled at the FEM's period: FemCoupling). haptic path
[[nodiscard]] double fem_contact_damping_n_s_per_m(const WorldModel& model,
                                                   const ContactMaterial& contact,
                                                   const LocalContactModel& fem_model,
                                                   double dt_s) noexcept;

}  // namespace hapsim
