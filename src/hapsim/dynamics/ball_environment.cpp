#include "hapsim/dynamics/ball_environment.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

namespace hapsim {

BallEnvironment::BallEnvironment(VirtualSheet& sheet, BallEnvironmentOptions options)
    : sheet_(&sheet),
      options_(std::move(options)),
      X_sheet_world_(options_.X_world_sheet.inverse()) {
  if (!options_.X_world_sheet.matrix().allFinite()) {
    throw Error("ball environment", "sheet pose must be finite");
  }
  // Depth of the sheet under a 1 N push, right under it: its compliance there.
  const double compliance_m_per_n = sheet.profile().depth_m(0.0, 1.0);
  const double k = options_.sheet_contact.stiffness_n_per_m;
  if (!(k > 0.0) || !(k * compliance_m_per_n < 1.0)) {
    throw Error("ball environment",
                "sheet contact stiffness " + std::to_string(k) +
                    " N/m must be > 0 and below the sheet's own stiffness under a contact (" +
                    std::to_string(1.0 / compliance_m_per_n) + " N/m)");
  }
}

BallContactReport BallEnvironment::step(RigidBall& ball, const Vec3& extra_force_world_n,
                                        double dt_s) noexcept {
  BallContactReport report;
  const double r = ball.params().radius_m;
  const Vec3 c_sheet = X_sheet_world_ * ball.p_world();
  const Mat3 R = options_.X_world_sheet.linear();

  // 1. Contact forces at the current state.
  const SheetSphereContact sc = sheet_->sphere_contact(c_sheet, r, SheetLayer::kElastic);
  if (sc.touching) {
    const Vec3 n_world = R * sc.normal_sheet;
    report.sheet_force_world_n =
        contact_spring_force(options_.sheet_contact, sc.penetration_m, n_world, ball.v_world(),
                             ball.p_world(), sheet_anchor_);
    report.on_sheet = report.sheet_force_world_n.squaredNorm() > 0.0;
  } else {
    sheet_anchor_.active = false;
  }
  if (options_.has_floor) {
    const double pen = options_.floor_z_m + r - ball.p_world().z();
    report.floor_force_world_n = contact_spring_force(
        options_.floor_contact, pen, Vec3::UnitZ(), ball.v_world(), ball.p_world(), floor_anchor_);
    report.on_floor = report.floor_force_world_n.squaredNorm() > 0.0;
  }

  // 2. The ball moves (a held ball is moved by its gripper instead).
  if (!ball.held()) {
    ball.step(report.sheet_force_world_n + report.floor_force_world_n + extra_force_world_n, dt_s);
  }

  // 3. The sheet takes the ball's push (the reaction to the sheet's upward push on the ball, into
  // the sheet) and its imprint.
  const double push_n = (R.transpose() * report.sheet_force_world_n).z();
  report.sheet_contact_sheet = sc.p_sheet;
  report.sheet_push_n = report.on_sheet ? std::max(push_n, 0.0) : 0.0;
  const std::array<SheetContact, 1> contacts{SheetContact{sc.p_sheet, report.sheet_push_n}};
  sheet_->apply_contacts(report.on_sheet ? std::span<const SheetContact>(contacts)
                                         : std::span<const SheetContact>());
  sheet_->imprint_sphere(X_sheet_world_ * ball.p_world(), r);
  return report;
}

}  // namespace hapsim
