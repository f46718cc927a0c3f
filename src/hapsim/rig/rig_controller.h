// The teleoperation rig as a controller on ordinary bodies (world/world_controller.h,
// architecture.md#controllers). The master arm is the device: in the place stage the slave
// follows the master's hand through IK and carries its links, palm, stem and gripper pads (all
// kinematic bodies of the world) to its joint frames, the pads closed to the master's grip, and the
// tool it carries (if any) at its flange; in the safety stage the pads', the gripper's and the
// carried tool's reaction at the slave's tool goes back to the master as joint torques (scaled,
// through the master's Jᵀ) and the grasp as finger torques. After the step
// it observes the result: whether the grasp holds, where the ball is and what carries it, how
// deep the sheet is dented. The ball, the sheet and the floor are ordinary bodies it only reads.
#pragma once

#include "hapsim/core/types.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/slave_follower.h"
#include "hapsim/rig/rig_description.h"
#include "hapsim/rig/rig_step_result.h"
#include "hapsim/world/world_controller.h"

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

namespace hapsim {

class World;
struct StepResult;

/// The rig's description and read-only model (the master arm), shared by the worlds built from
/// one description (WorldDescription::controller).
class RigController final : public WorldController {
 public:
  /// Throws hapsim::Error ("teleop: …") on a rig it cannot drive: no slave, a start of the wrong
  /// size, unusable gripper pads, a non-finite ball start or force scale.
  explicit RigController(TeleopRigDescription description);

  [[nodiscard]] std::string_view kind() const noexcept override { return "rig"; }
  /// The rig's bodies are where rig_world() or add_rig() put them, of the kinds it drives and
  /// reads; its carried tool is device 0's, with no finger.
  void check(const WorldDescription& world) const override;
  void fingerprint(ContentFingerprint& h) const override;
  [[nodiscard]] std::unique_ptr<ControllerState> make_state(const WorldModel& model) const override;

  [[nodiscard]] const TeleopRigDescription& description() const noexcept { return description_; }
  [[nodiscard]] const MasterArm& master() const noexcept { return master_; }
  /// The slave gripper's opening for a master grip opening: the master's range mapped linearly
  /// onto the slave's.
  [[nodiscard]] double slave_width_for(double master_opening_m) const noexcept;

  /// The master's command for a force at the slave's tool (world frame) and a grasp force: the
  /// force scaled (force_scale) into the master's frame through the master's Jᵀ at `arm_rad`, the
  /// grasp through its fingers and on both finger channels; a non-finite torque or grasp is zero.
  /// What the rig's command writes each step, and what a device host playing the master renders
  /// from a served contact model (net/device_host_client.h). haptic path
  void master_command(const std::array<double, 3>& arm_rad, const Vec3& force_at_slave_tool_world_n,
                      double grasp_force_n, DeviceCommand& command) const noexcept;
  /// Where a point fixed in the slave's flange frame (a carried tool's centre, `p_flange_m`) is
  /// when the slave stands on the target this master input asks for: the follower's lag left out,
  /// the device host's stand-in for where the served slave carries its tool. NaN when the input
  /// is not a master's (fewer than three finite arm joints). haptic path
  [[nodiscard]] Vec3 flange_point_target_world(const DeviceInput& input,
                                               const Vec3& p_flange_m) const noexcept;
  /// Where gripper pad `pad` (0: the +y side) is centred when the slave stands on the target
  /// this master input asks for and its pads stand at the opening the master's grip asks: the
  /// follower's and the gripper's lag left out, and the stop at the gripper's force limit (the
  /// pads' served models cap their push there). The device host's stand-in for where the served
  /// slave holds that pad. NaN when the input is not a master's (three arm joints and two
  /// fingers, all finite). haptic path
  [[nodiscard]] Vec3 pad_centre_target_world(const DeviceInput& input,
                                             std::size_t pad) const noexcept;

 private:
  TeleopRigDescription description_;
  MasterArm master_;
};

/// Per-world state of a rig: the slave following the master and the bodies it carries (place),
/// the master's torques (command), the grasp, ball and sheet report (observe).
class RigState final : public ControllerState {
 public:
  /// Throws hapsim::Error on unusable slave settings.
  RigState(const RigController& controller, const WorldModel& model);
  ~RigState() override;

  void reset() noexcept override;
  void place(const WorldModel& model, WorldState& state, const DeviceInput& input,
             DeviceInput& tool_input, double dt_s) noexcept override;
  void command(const WorldModel& model, const WorldState& state,
               DeviceCommand& command) noexcept override;
  void observe(const WorldModel& model, const StepResult& result) noexcept override;

  const RigController* controller = nullptr;          ///< the model's; outlives this state
  const TeleopRigDescription* description = nullptr;  ///< controller->description()
  std::vector<double> slave_start_rad;                ///< the slave's start joints, dof() values

  std::unique_ptr<SlaveFollower> slave;
  /// Place stage: the master's input was usable (healthy, finite joints).
  bool input_usable = false;
  /// Place stage: the pads' centres last step (their velocity), world frame.
  std::array<Vec3, 2> pad_previous_world{Vec3::Zero(), Vec3::Zero()};
  Mat3 tool_previous_R = Mat3::Identity();
  bool has_pad_previous = false;
  /// Place stage: the slave's joint frames this step (dof(), sized at construction).
  std::vector<Iso3> frames;
  /// Place stage: each slave body's pose last step (TeleopRigDescription::slave_bodies order),
  /// for its velocity.
  std::vector<Iso3> slave_body_previous;

  /// A slave collision is counted when a slave body's surface is deeper than this inside another
  /// body (a graze is not a hit).
  static constexpr double kCollisionDepthM = 1e-3;
  /// What the place stage checks for slave collisions (built with the state): the slave's bodies
  /// (not its base and waist — the links on the base frame and joint 0's frame — which stand on
  /// the robot's mount; their sphere trees are the body-contact stage's), and the bodies they
  /// cannot push back (static and deformable) with their segments' world bounds (those bodies
  /// never move).
  struct Collider {
    std::size_t body = 0;
    std::size_t flat = 0;  ///< its segment
  };
  struct Obstacle {
    std::size_t body = 0;
    std::size_t flat = 0;
    Box3 bounds_world;
  };
  std::vector<Collider> colliders;
  std::vector<Obstacle> obstacles;
  /// The rig's sheet among the world's sheets (StepResult::sheet_depth_m's index).
  std::size_t sheet_index = 0;

  /// Observed: the grasp holds (both pads press the ball from opposite sides hard enough that
  /// friction carries its weight). A report: the ball is held by friction, not attached.
  bool held = false;
  /// Observed: when a held grasp's pad left the ball (-1: none has), for its release's delay.
  double grip_lost_since_s = -1.0;
  TeleopStepResult result;
};

/// The rig a world description drives, or null when it has none (another controller, or none).
[[nodiscard]] const RigController* rig_controller(const WorldDescription& world) noexcept;
/// Its description, or null.
[[nodiscard]] const TeleopRigDescription* rig_description(const WorldDescription& world) noexcept;
/// A world's rig state (slave, gripper, last step), or null when the world has no rig. Only the
/// thread that steps may read it while the world runs.
[[nodiscard]] const RigState* rig_state(const World& world) noexcept;
/// The rig's step in a world's step result, or null when the world has no rig.
[[nodiscard]] const TeleopStepResult* rig_result(const StepResult& result) noexcept;

/// Finds the slave's collision pairs (place stage): its bodies that can hit something and the
/// bodies they cannot push back (slave_collisions.cpp).
void find_slave_collision_pairs(const WorldModel& model, RigState& rig);
/// Counts this step's slave collisions into rig.result (place stage). haptic path
void count_slave_collisions(const WorldModel& model, RigState& rig,
                            const WorldState& state) noexcept;

}  // namespace hapsim
