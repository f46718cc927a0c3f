// Stage 4: rigid bodies. Each dynamic body moves under gravity and this step's contact forces
// (tools in the respond stage, other bodies in the body-contact stage) by semi-implicit
// (symplectic) Euler — v += (F/m + g)·dt, then x += v·dt; ω += I⁻¹(τ − ω×Iω)·dt, then the
// orientation turns by ω·dt — which stays stable for stiff penalty contacts at 1 kHz where
// explicit Euler gains energy. The rig's ball moves under gravity and the gripper pads' force and
// rests on its virtual sheet or the floor (its own contact springs, dynamics/ball_environment.h).
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <cmath>

namespace hapsim::stage {

namespace {

// haptic path
void integrate_body(const BodyModel& bm, const Vec3& gravity, BodyState& body,
                    double dt_s) noexcept {
  if (!body.force_world_n.allFinite() || !body.torque_world_nm.allFinite()) {
    // A non-finite contact force is dropped: the body never becomes NaN.
    body.force_world_n.setZero();
    body.torque_world_nm.setZero();
  }
  const Mat3 R = body.X_world_body.linear();
  Vec3 com = body.X_world_body * bm.com_body;
  body.v_world += (body.force_world_n / bm.mass_kg + gravity) * dt_s;
  com += body.v_world * dt_s;
  const Mat3 inertia_world = R * bm.inertia_body_kg_m2 * R.transpose();
  const Mat3 inverse_world = R * bm.inverse_inertia_body * R.transpose();
  body.w_world += inverse_world *
                  (body.torque_world_nm - body.w_world.cross(inertia_world * body.w_world)) * dt_s;
  const double angle = body.w_world.norm() * dt_s;
  Mat3 R_next = R;
  if (angle > 0.0) {
    R_next = Eigen::AngleAxisd(angle, body.w_world.normalized()).toRotationMatrix() * R;
    // Keep the rotation orthonormal over millions of steps.
    R_next = Quat(R_next).normalized().toRotationMatrix();
  }
  body.X_world_body.linear() = R_next;
  body.X_world_body.translation() = com - R_next * bm.com_body;
  body.X_body_world = body.X_world_body.inverse();
}

}  // namespace

// haptic path
void integrate(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  const Vec3& gravity = model.description().gravity_m_per_s2;
  for (const std::size_t b : model.dynamic_bodies()) {
    integrate_body(model.bodies()[b], gravity, state.bodies[b], dt_s);
  }
  if (!state.rig) {
    return;
  }
  RigState& rig = *state.rig;
  TeleopStepResult& r = rig.result;
  r.ball_contacts = rig.environment->step(rig.ball, r.gripper.force_on_ball_world_n, dt_s);
  r.ball_p_world = rig.ball.p_world();
  r.held = r.gripper.held;
  r.sheet_depth_m = rig.sheet->max_depth_m();
}

}  // namespace hapsim::stage
