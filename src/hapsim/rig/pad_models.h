// The gripper pads' local contact models (force/local_contact_model.h): what a served rig's
// master feels of the grasp. The pads are kinematic bodies, not tools, so the world's model
// builder (world/local_model_builder.h) makes none for them; each pad's contact with the ball is
// linearised here as the force on the pad, F = f0 − K·(x − x0), K the pad spring along the
// contact's normal, its push capped at the gripper's force limit (where place_pads stops the
// pads). x is the pad's place in the grip's frame (world axes, origin at the pads' midpoint):
// the ball is free between the pads and goes where they take it, so the hand carrying the grip
// moves nothing in that frame and only the grip's opening (and its turn) squeezes the ball. Two
// models at the pads' world places would render a sideways move of the hand as one pad's spring
// pushing and the other's pulling, and each new model, evaluated where the last left the pad,
// as a step of K times the distance the carry moved it in a cycle. The simulation host serves them
// beside the carried tool's (net/model_publisher.h) and the master's host renders them where the
// slave's target puts each pad (RigController::pad_centre_target_world): their sum is the pads'
// reaction at the slave's tool, their push the grasp on the master's fingers, as the rig's own
// command makes them.
#pragma once

#include "hapsim/force/local_contact_model.h"
#include "hapsim/rig/rig_description.h"

#include <array>
#include <cstdint>

namespace hapsim {

struct WorldState;

/// Each pad's model this step (0: the +y pad): free space (invalid) where the pad does not touch
/// the ball or the rig grasps nothing (grasps_ball). `sequence` numbers them and
/// `validity_radius_m` is how far from the pad's centre the device may trust them. haptic path
void build_pad_models(const TeleopRigDescription& rig, const WorldState& state,
                      std::uint64_t sequence, double validity_radius_m,
                      std::array<LocalContactModel, 2>& models) noexcept;

}  // namespace hapsim
