// The stages of one world step, in the order step() (world_step.h) runs them. Each reads the
// read-only model and the state fields earlier stages filled, and fills its own (world_state.h
// says which stage fills what). All are haptic path: no allocation, no lock, no I/O.
//
//   place_tools      device input → the world's controller (world_controller.h) moves the bodies
//                    it drives (a robot's links and gripper pads); then each tool's position and
//                    velocity (probe: device pose × offset; glove: the hand's fingertips; a
//                    controller may put them where its mechanism holds them); an unusable input
//                    holds the tools
//   detect_contacts  penalty segments: each tool against each segment's rest surface (a sheet: its
//                    live field), which side it presses from (never pulled through a thin
//                    segment), less the dent others left under it
//   body_contacts    each dynamic body against every other body's segments through both bodies'
//                    sphere trees, refined exactly (a sphere's centre, a mesh's vertices): springs
//                    of both materials in series, with friction, equal and opposite on both;
//                    pushes on sheets
//   respond          proxy segments: the god-object moves its proxy and the spring gives the force;
//                    penalty segments: F = k·x with damping and friction, the reaction on a dynamic
//                    body, the push on a sheet; contacts reported, deformation fed
//   fem_contacts     FEM bodies: the local contact model the FEM thread handed over, at the tool's
//                    fresh position (series stiffness, damping floor, cap, push-only)
//   integrate        dynamic bodies move under gravity and this step's forces (semi-implicit Euler,
//                    the contacts' springs and dampers taken implicitly)
//   deform           deformable segments deflect under this step's contacts (eq. 1), the rest
//                    recover; sheets take this step's pushes and the imprint of resting spheres
//   safety           what leaves the world is finite: per-tool forces, then the device command
//                    (finger channels and tip force; a controller writes its own: a master arm's
//                    joint and finger torques through Jᵀ); zero for an unusable input
//
// After the stages the controller observes the step's result, read-only, for its own reports.
#pragma once

#include "hapsim/core/device_io.h"
#include "hapsim/core/types.h"

namespace hapsim {

class WorldModel;
struct WorldState;
struct SegmentState;
struct BodyState;
struct BodyModel;
struct ContactMaterial;

namespace stage {

void place_tools(const WorldModel& model, WorldState& state, const DeviceInput& input,
                 double dt_s) noexcept;
/// Longest input time a tool's velocity is differenced over; a longer gap is a jump.
inline constexpr double kMaxInputMotionTime_s = 0.1;
/// How long the device took for the motion between two inputs, by the input's own time stamps:
/// a served world steps on a remote device's states, and after a stall on either side one step
/// holds several of the device's periods of motion; differenced over the step (dt_s) it would be
/// a velocity, and a damping force, many times the device's. dt_s when the stamps say nothing
/// better (equal to the step within 1 %, not increasing, or more than kMaxInputMotionTime_s).
[[nodiscard]] double input_motion_time_s(double input_time_s, double input_time_previous_s,
                                         double dt_s) noexcept;
void detect_contacts(const WorldModel& model, WorldState& state, double dt_s) noexcept;
/// Dynamic bodies against every other body's segments (detection and response in one: a body's
/// contacts are found and answered where they are found; stage_body_contacts.cpp).
void body_contacts(const WorldModel& model, WorldState& state, double dt_s) noexcept;
void respond(const WorldModel& model, WorldState& state, double dt_s) noexcept;
/// FEM bodies: each tool's local contact model from the FEM side, rendered at the tool's fresh
/// position (stage_fem_contacts.cpp); the force is added to the tool's and kept as the FEM's load.
void fem_contacts(const WorldModel& model, WorldState& state, double dt_s) noexcept;
void integrate(const WorldModel& model, WorldState& state, double dt_s) noexcept;
void deform(const WorldModel& model, WorldState& state, double dt_s) noexcept;
void safety(const WorldModel& model, WorldState& state) noexcept;

/// The contact spring of a penalty contact (normal n_world, force magnitude force_n, at
/// p_world; its other end moving at v_anchor_world) on a dynamic body, for the integrate stage
/// to take implicitly; nothing where the force is clamped (zero, the force or depth cap).
/// haptic path
void linearise_penalty(BodyState& body, const BodyModel& bm, const Vec3& p_world,
                       const Vec3& n_world, const ContactMaterial& material, double depth_m,
                       double force_n, const Vec3& v_anchor_world) noexcept;
/// The spring S and damper D (world frame) of a penalty contact or a sticking friction contact,
/// where their force law is linear; false where it is clamped (no spring). haptic path
bool penalty_spring(const ContactMaterial& material, const Vec3& n_world, double depth_m,
                    double force_n, Mat3& S, Mat3& D) noexcept;
bool friction_spring(const ContactMaterial& material, const Vec3& n_world, double normal_force_n,
                     const Vec3& f_friction_n, Mat3& S, Mat3& D) noexcept;
/// The same for a friction stick spring (tangential), only while it sticks. haptic path
void linearise_friction(BodyState& body, const BodyModel& bm, const Vec3& p_world,
                        const Vec3& n_world, const ContactMaterial& material, double normal_force_n,
                        const Vec3& f_friction_n, const Vec3& v_anchor_world) noexcept;

/// A push on a sheet segment this step: the force that pushes the presser out, at `p_world`;
/// the deform stage displaces the sheet by it.
void add_sheet_push(SegmentState& sheet, const Iso3& X_sheet_world, const Vec3& p_world,
                    const Vec3& force_on_presser_world_n) noexcept;

}  // namespace stage
}  // namespace hapsim
