#include "hapsim/rig/pad_models.h"

#include "hapsim/world/world_state.h"

namespace hapsim {

// haptic path
void build_pad_models(const TeleopRigDescription& rig, const WorldState& state,
                      std::uint64_t sequence, double validity_radius_m,
                      std::array<LocalContactModel, 2>& models) noexcept {
  const bool grasps = grasps_ball(rig);
  for (std::size_t i = 0; i < 2; ++i) {
    LocalContactModel& m = models[i];
    m = LocalContactModel{};
    m.sequence = sequence;
    m.sim_time_s = state.time_s;
    if (!grasps) {
      continue;
    }
    // The ball's contacts with this pad (body-contact stage): each is the force on the ball, its
    // normal out of the pad; the pad takes the opposite.
    Vec3 on_pad_n = Vec3::Zero();
    Vec3 out_of_ball = Vec3::Zero();
    bool touching = false;
    for (std::size_t k = 0; k < state.body_contact_count; ++k) {
      const BodyContact& c = state.body_contacts[k];
      if (c.body == BodyIndex{rig.ball_body} && c.other_body == BodyIndex{rig.pad_body[i]}) {
        on_pad_n -= c.force_world_n;
        out_of_ball -= c.normal_world;
        touching = true;
      }
    }
    const double length = out_of_ball.norm();
    if (!touching || !(length > 0.0) || !on_pad_n.allFinite()) {
      continue;  // free space
    }
    const Vec3 n = out_of_ball / length;
    const BodyState& pad = state.bodies[rig.pad_body[i]];
    const BodyState& other = state.bodies[rig.pad_body[1 - i]];
    // In the grip's frame (world axes, origin at the pads' midpoint): the ball is free between
    // the pads and goes where they take it, so only the pads' motion relative to each other
    // squeezes it; the hand carrying the grip moves nothing here.
    m.x0_world_m = 0.5 * (pad.X_world_body.translation() - other.X_world_body.translation());
    m.v0_world_m_per_s = 0.5 * (pad.v_world - other.v_world);
    m.f0_world_n = on_pad_n;
    // The pad's spring along the normal; no damping: the pads move as the slave's gripper does,
    // not as the master's grip asks, so a velocity difference here is lag, not a contact's rate.
    m.stiffness_n_per_m = rig.gripper.pad_contact.stiffness_n_per_m * (n * n.transpose());
    m.normal_world = n;
    m.validity_radius_m = validity_radius_m;
    m.max_normal_force_n = rig.gripper.max_force_n;
    m.valid = true;
  }
}

}  // namespace hapsim
