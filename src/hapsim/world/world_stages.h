// The stages of one world step, in the order step() (world_step.h) runs them. Each reads the
// read-only model and the state fields earlier stages filled, and fills its own (world_state.h
// says which stage fills what). All are haptic path: no allocation, no lock, no I/O.
//
//   place_tools      device input → each tool's position and velocity (probe: device pose × offset;
//                    glove: the hand's fingertips); an unusable input holds the tools
//   detect_contacts  penalty segments: each tool against each segment's rest surface, which side
//                    it presses from (never pulled through a thin segment)
//   respond          proxy segments: the god-object moves its proxy and the spring gives the force;
//                    penalty segments: F = k·x with damping; contacts reported, deformation fed
//   deform           deformable segments deflect under this step's contacts (eq. 1), the rest
//                    recover
//   safety           what leaves the world is finite: per-tool forces, then the device command
//                    (finger channels and tip force); zero for an unusable input
//
// Rigid-body integration (the grasped ball) and the virtual sheet still step inside TeleopWorld
// (teleop_world.h) until the teleoperation scene joins this world.
#pragma once

#include "hapsim/core/device_io.h"

namespace hapsim {

class WorldModel;
struct WorldState;

namespace stage {

void place_tools(const WorldModel& model, WorldState& state, const DeviceInput& input,
                 double dt_s) noexcept;
void detect_contacts(const WorldModel& model, WorldState& state) noexcept;
void respond(const WorldModel& model, WorldState& state) noexcept;
void deform(const WorldModel& model, WorldState& state, double dt_s) noexcept;
void safety(const WorldModel& model, WorldState& state) noexcept;

}  // namespace stage
}  // namespace hapsim
