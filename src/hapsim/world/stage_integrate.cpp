// Stage 4: rigid bodies. Each dynamic body moves under gravity and this step's contact forces
// (tools in the respond stage, other bodies in the body-contact stage) by semi-implicit
// (symplectic) Euler — v += (F/m + g)·dt, then x += v·dt; ω += I⁻¹(τ − ω×Iω)·dt, then the
// orientation turns by ω·dt — with the contacts' springs and dampers (linearised where the stages
// computed them) taken implicitly in the velocity update, so a light body on stiff contacts
// stays stable at 1 kHz where explicit Euler gains energy (a ball a robot's gripper picks is one
// of these bodies).
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

#include <Eigen/Cholesky>

#include <cmath>

namespace hapsim::stage {

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// The velocity change Δ = [Δv; Δω] when contact springs act: linearly implicit Euler (Baraff &
// Witkin), F(x + dt·v⁺, v⁺) ≈ F + ∂F/∂x·dt·v⁺ + ∂F/∂v·(v⁺ − v) with ∂F/∂x = −K, ∂F/∂v = −C, gives
// (M + dt·C + dt²·K)·Δ = dt·F − dt²·(K·v − Σ Jᵀ·S·v_anchor) (the springs' other ends move too),
// plus (dt·C_ij + dt²·K_ij)·Δ_j for each dynamic body j it touches (solved together below).
// Unconditionally stable for the springs, where the explicit update of a 50 g cube on four
// 10 kN/m corner springs at 1 kHz rings and gains energy. Factorises and solves without the
// other bodies' Δ. haptic path
void begin_implicit(const BodyModel& bm, const Mat3& inertia_world, const Vec3& gravity,
                    BodyState& body, double dt_s) noexcept {
  Mat6 A = dt_s * body.damping_6 + (dt_s * dt_s) * body.stiffness_6;
  A.topLeftCorner<3, 3>() += bm.mass_kg * Mat3::Identity();
  A.bottomRightCorner<3, 3>() += inertia_world;
  Vec6 v;
  v << body.v_world, body.w_world;
  body.rhs_6 << (body.force_world_n + bm.mass_kg * gravity) * dt_s,
      (body.torque_world_nm - body.w_world.cross(inertia_world * body.w_world)) * dt_s;
  body.rhs_6.noalias() -= (dt_s * dt_s) * (body.stiffness_6 * v - body.anchor_6);
  body.dv_6 = A.ldlt().solve(body.rhs_6);
  body.system_6 = A;  // the coupled sweeps invert it when the body touches another
  body.implicit = true;
}

// haptic path
void begin_velocities(const BodyModel& bm, const Vec3& gravity, BodyState& body,
                      double dt_s) noexcept {
  if (!body.force_world_n.allFinite() || !body.torque_world_nm.allFinite() ||
      !body.stiffness_6.allFinite() || !body.damping_6.allFinite() || !body.anchor_6.allFinite()) {
    // A non-finite contact force is dropped: the body never becomes NaN.
    body.force_world_n.setZero();
    body.torque_world_nm.setZero();
    body.stiffness_6.setZero();
    body.damping_6.setZero();
    body.anchor_6.setZero();
  }
  const Mat3 R = body.X_world_body.linear();
  const Mat3 inertia_world = R * bm.inertia_body_kg_m2 * R.transpose();
  body.implicit = false;
  if (body.stiffness_6.isZero(0.0) && body.damping_6.isZero(0.0)) {
    // In flight: semi-implicit Euler as it is.
    body.v_world += (body.force_world_n / bm.mass_kg + gravity) * dt_s;
    const Mat3 inverse_world = R * bm.inverse_inertia_body * R.transpose();
    body.w_world += inverse_world *
                    (body.torque_world_nm - body.w_world.cross(inertia_world * body.w_world)) *
                    dt_s;
  } else {
    begin_implicit(bm, inertia_world, gravity, body, dt_s);
  }
}

// Dynamic bodies touching each other: block Gauss-Seidel over their coupled systems (the whole
// matrix is symmetric positive definite, so the sweeps converge); without it each would take the
// other's old velocity, as stable as explicit Euler (two stacked 25 g cubes shook from 24 kN/m).
constexpr int kCouplingSweeps = 6;

// haptic path
void solve_couplings(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  const std::vector<std::size_t>& dynamic = model.dynamic_bodies();
  const std::size_t n = dynamic.size();
  bool any = false;
  for (const BodyCoupling& c : state.couplings) {
    any = any || c.active;
  }
  if (!any) {
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    BodyState& body = state.bodies[dynamic[i]];
    bool coupled = false;
    for (std::size_t j = 0; j < n; ++j) {
      coupled = coupled || (j != i && state.couplings[i * n + j].active);
    }
    if (body.implicit && coupled) {
      body.inverse_6 = body.system_6.ldlt().solve(Mat6::Identity());
    }
  }
  for (int sweep = 0; sweep < kCouplingSweeps; ++sweep) {
    for (std::size_t i = 0; i < n; ++i) {
      BodyState& body = state.bodies[dynamic[i]];
      if (!body.implicit) {
        continue;
      }
      Vec6 rhs = body.rhs_6;
      bool coupled = false;
      for (std::size_t j = 0; j < n; ++j) {
        const BodyCoupling& c = state.couplings[i * n + j];
        if (j == i || !c.active || !state.bodies[dynamic[j]].implicit) {
          continue;
        }
        rhs.noalias() +=
            (dt_s * c.damping_6 + (dt_s * dt_s) * c.stiffness_6) * state.bodies[dynamic[j]].dv_6;
        coupled = true;
      }
      if (coupled) {
        body.dv_6.noalias() = body.inverse_6 * rhs;
      }
    }
  }
}

// haptic path
void move_body(const BodyModel& bm, BodyState& body, double dt_s) noexcept {
  if (body.implicit) {
    body.v_world += body.dv_6.head<3>();
    body.w_world += body.dv_6.tail<3>();
  }
  const Mat3 R = body.X_world_body.linear();
  Vec3 com = body.X_world_body * bm.com_body;
  com += body.v_world * dt_s;
  const double angle = body.w_world.norm() * dt_s;
  Mat3 R_next = R;
  if (angle > 0.0) {
    R_next = Eigen::AngleAxisd(angle, body.w_world.normalized()).toRotationMatrix() * R;
    // Keep the rotation orthonormal over millions of steps.
    R_next = Quat(R_next).normalized().toRotationMatrix();
  }
  if (!com.allFinite() || !R_next.allFinite() || !body.v_world.allFinite() ||
      !body.w_world.allFinite()) {
    // Overflowed (a mass or inertia too small for the forces): stay put rather than go NaN.
    body.v_world.setZero();
    body.w_world.setZero();
    return;
  }
  body.X_world_body.linear() = R_next;
  body.X_world_body.translation() = com - R_next * bm.com_body;
  body.X_body_world = body.X_world_body.inverse();
}

}  // namespace

// haptic path
bool penalty_spring(const ContactMaterial& material, const Vec3& n_world, double depth_m,
                    double force_n, Mat3& S, Mat3& D) noexcept {
  // Only where F = k·x + b·v holds: not clamped at zero, at the force cap or the depth cap.
  if (!(force_n > 0.0) || !(force_n < material.max_force_n) ||
      !(depth_m < material.max_penetration_m) || !std::isfinite(material.stiffness_n_per_m) ||
      !std::isfinite(material.damping_n_s_per_m)) {
    return false;
  }
  const Mat3 nn = n_world * n_world.transpose();
  S = material.stiffness_n_per_m * nn;
  D = material.damping_n_s_per_m * nn;
  return true;
}

// haptic path
bool friction_spring(const ContactMaterial& material, const Vec3& n_world, double normal_force_n,
                     const Vec3& f_friction_n, Mat3& S, Mat3& D) noexcept {
  // Only while it sticks: slipping friction is μd·N whatever the motion (no spring).
  const double slipping_n = material.dynamic_friction * normal_force_n;
  if (!(normal_force_n > 0.0) || !(material.static_friction > 0.0) ||
      std::abs(f_friction_n.norm() - slipping_n) <= 1e-9 * slipping_n ||
      !std::isfinite(material.stiffness_n_per_m) || !std::isfinite(material.damping_n_s_per_m)) {
    return false;
  }
  const Mat3 tangent = Mat3::Identity() - n_world * n_world.transpose();
  S = material.stiffness_n_per_m * tangent;
  D = material.damping_n_s_per_m * tangent;
  return true;
}

// haptic path
void linearise_penalty(BodyState& body, const BodyModel& bm, const Vec3& p_world,
                       const Vec3& n_world, const ContactMaterial& material, double depth_m,
                       double force_n, const Vec3& v_anchor_world) noexcept {
  Mat3 S;
  Mat3 D;
  if (body.dynamic && penalty_spring(material, n_world, depth_m, force_n, S, D)) {
    body.add_contact_spring(p_world, bm.com_body, S, D, v_anchor_world);
  }
}

// haptic path
void linearise_friction(BodyState& body, const BodyModel& bm, const Vec3& p_world,
                        const Vec3& n_world, const ContactMaterial& material, double normal_force_n,
                        const Vec3& f_friction_n, const Vec3& v_anchor_world) noexcept {
  Mat3 S;
  Mat3 D;
  if (body.dynamic && friction_spring(material, n_world, normal_force_n, f_friction_n, S, D)) {
    body.add_contact_spring(p_world, bm.com_body, S, D, v_anchor_world);
  }
}

// haptic path
void integrate(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  const Vec3& gravity = model.description().gravity_m_per_s2;
  for (const std::size_t b : model.dynamic_bodies()) {
    begin_velocities(model.bodies()[b], gravity, state.bodies[b], dt_s);
  }
  solve_couplings(model, state, dt_s);
  for (const std::size_t b : model.dynamic_bodies()) {
    move_body(model.bodies()[b], state.bodies[b], dt_s);
  }
}

}  // namespace hapsim::stage
