#include "hapsim/world/teleop_world.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cmath>

namespace hapsim {

namespace {

TeleopWorldDescription checked(TeleopWorldDescription d) {
  if (!d.slave) {
    throw Error("teleop", "no slave arm");
  }
  if (!d.slave_start_rad.empty() &&
      d.slave_start_rad.size() != static_cast<std::size_t>(d.slave->dof())) {
    throw Error("teleop", "slave start has " + std::to_string(d.slave_start_rad.size()) +
                              " joint values; the slave has " + std::to_string(d.slave->dof()));
  }
  if (!d.ball_start_world.allFinite() || !std::isfinite(d.force_scale) || d.force_scale < 0.0) {
    throw Error("teleop", "ball start must be finite and the force scale >= 0");
  }
  return d;
}

std::vector<double> start_joints(const TeleopWorldDescription& d) {
  return d.slave_start_rad.empty() ? std::vector<double>(static_cast<std::size_t>(d.slave->dof()))
                                   : d.slave_start_rad;
}

}  // namespace

TeleopWorld::TeleopWorld(TeleopWorldDescription description)
    : description_(checked(std::move(description))),
      master_(description_.master),
      slave_(std::make_unique<SlaveFollower>(*description_.slave, start_joints(description_),
                                             description_.follower)),
      gripper_(description_.gripper),
      ball_(description_.ball, description_.ball_start_world),
      sheet_(std::make_unique<VirtualSheet>(description_.sheet)),
      environment_(std::make_unique<BallEnvironment>(*sheet_, description_.environment)) {}

double TeleopWorld::slave_width_for(double master_opening_m) const noexcept {
  const MasterArmGeometry& g = master_.geometry();
  const double widest = 2.0 * g.finger_m * std::sin(g.finger_open_limit_rad);
  const double u = std::clamp((master_opening_m - g.finger_gap_m) / widest, 0.0, 1.0);
  return u * description_.follower.gripper_max_width_m;
}

const TeleopStepResult& TeleopWorld::step(const DeviceInput& master, double dt_s) noexcept {
  const double dt = std::isfinite(dt_s) && dt_s > 0.0 ? dt_s : 0.0;
  time_s_ += dt;
  result_.time_s = time_s_;
  result_.command = DeviceCommand{};
  const std::array<double, 3> arm{master.joint_rad[0], master.joint_rad[1], master.joint_rad[2]};
  const std::array<double, 2> fingers{master.finger_rad[0], master.finger_rad[1]};
  bool usable = master.healthy;
  for (const double v : {arm[0], arm[1], arm[2], fingers[0], fingers[1]}) {
    usable = usable && std::isfinite(v);
  }

  // 1. Master → slave target; the slave follows (or holds still on a bad input).
  double width_command = slave_->gripper_width_m();
  if (usable) {
    result_.master_arm_rad = arm;
    result_.master_finger_rad = fingers;
    result_.master_hand = master_.hand_pose(arm);
    const Iso3 target =
        slave_target(description_.mapping, result_.master_hand.translation(), arm[0]);
    width_command = slave_width_for(master_.grip_opening_m(fingers));
    result_.slave = slave_->step(target, width_command, dt);
  } else {
    result_.slave = slave_->step(slave_->tip_pose(), width_command, dt);
  }
  result_.slave_tool = slave_->tip_pose();

  // 2. Gripper pads vs the ball; then the ball on the sheet and the floor.
  result_.gripper = gripper_.step(result_.slave_tool, slave_->gripper_width_m(), ball_, dt);
  result_.ball_contacts = environment_->step(ball_, result_.gripper.force_on_ball_world_n, dt);
  result_.ball_p_world = ball_.p_world();
  result_.held = result_.gripper.held;
  result_.sheet_depth_m = sheet_->max_depth_m();

  // 3. Forces back to the master: the pads' reaction at the slave's tool (plus, while held, the
  // ball's weight and whatever the sheet pushes on it), scaled into the master's frame.
  if (usable) {
    Vec3 at_tool = -result_.gripper.force_on_ball_world_n;
    if (result_.held) {
      at_tool = ball_.params().mass_kg * ball_.params().gravity_m_per_s2 +
                result_.ball_contacts.sheet_force_world_n +
                result_.ball_contacts.floor_force_world_n;
    }
    const Vec3 at_master = description_.mapping.X_slave_master.linear().transpose() * at_tool *
                           description_.force_scale;
    const MasterTorques t = master_.torques(arm, at_master, result_.gripper.grasp_force_n());
    for (std::size_t i = 0; i < 3; ++i) {
      result_.command.joint_torque_nm[i] = t.arm_n_m[i];
    }
    result_.command.joint_torque_nm[3] = t.fingers_n_m[0];
    result_.command.joint_torque_nm[4] = t.fingers_n_m[1];
    result_.command.joint_count = 5;
    result_.command.finger_force_n[0] = result_.gripper.grasp_force_n();
    result_.command.finger_force_n[1] = result_.gripper.grasp_force_n();
    result_.command.finger_count = 2;
  }
  return result_;
}

}  // namespace hapsim
