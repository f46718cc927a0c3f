// A position device (the viewer's mouse probe, a 3D mouse) driving a teleoperation rig's 5-DOF
// master arm, which wants joints: MasterHandMapping turns the probe's position (where the slave's
// tool should go; the master's hand through the inverse teleoperation mapping) into the master's
// arm joints with the master's own position IK — as the scripted pick-and-place does — and the
// grasp button into the two finger joints. It runs inside the device's read() on the haptic thread
// (MasterProbeDevice): solve_ik allocates nothing, the answer is cached (IK runs only when the
// probe moved, i.e. at most once per viewer frame) and bounded (tracked from the last answer, a
// few restarts), and the same adapter serves the mouse and the 3D mouse, whose reader thread hands
// its pose straight to the haptic thread.
#pragma once

#include "hapsim/device/device.h"
#include "hapsim/kinematics/inverse_kinematics.h"
#include "hapsim/kinematics/master_arm.h"
#include "hapsim/kinematics/slave_follower.h"

#include <array>
#include <utility>

namespace hapsim {

/// A probe's input → the 5-DOF master's input: `p_world` is where the master's hand should be
/// (the master's base frame, metres); buttons bit 0 closes the grasp.
class MasterHandMapping {
 public:
  /// `seed_rad`: the arm joints to track from (the trajectory's first sample). The open grasp is
  /// the slave gripper's full width mapped back through the master geometry as the scripted
  /// pick-and-place maps widths: pads finger_gap + 2·finger·sin(open limit) apart.
  MasterHandMapping(MasterArm master, const std::array<double, 3>& seed_rad);

  /// The master input for `probe`: joint_rad[0..2] (joint_count 3) placing the hand at
  /// probe.p_world (or as close as the arm reaches), finger_rad[0..1] (finger_count 2) closed
  /// (angle 0) with buttons bit 0 set, else fully open; time, health and buttons passed through,
  /// the probe's other joints and fingers dropped. A non-finite position keeps the last joints.
  /// haptic path (no allocation)
  [[nodiscard]] DeviceInput master_input(const DeviceInput& probe) noexcept;

  /// From now on the probe's p_world is where the SLAVE's tool should be (world = slave base
  /// frame), as the viewer's cursor points at the slave: the hand target is the mapping inverted,
  /// X_slave_master⁻¹·p / scale. Without this call p_world is the hand position itself.
  void set_probe_in_slave_frame(const TeleopMapping& mapping);
  /// Where the probe sits for master arm joints `arm_rad` (the inverse of the above).
  [[nodiscard]] Vec3 probe_for(const std::array<double, 3>& arm_rad) const;

  [[nodiscard]] const MasterArm& master() const { return master_; }
  /// The arm joints of the last answer, and whether its IK reached the probe (within 0.1 mm).
  [[nodiscard]] const std::array<double, 3>& arm_rad() const { return arm_rad_; }
  [[nodiscard]] bool reached() const { return reached_; }
  /// Finger angle of the open grasp, radians.
  [[nodiscard]] double open_finger_rad() const { return open_finger_rad_; }

 private:
  MasterArm master_;
  IkOptions ik_;
  std::array<double, 3> arm_rad_{};
  Vec3 solved_for_ = Vec3::Constant(kInf);
  bool probe_in_slave_frame_ = false;
  double scale_ = 1.0;
  Iso3 X_master_slave_ = Iso3::Identity();
  bool reached_ = false;
  double open_finger_rad_ = 0.0;
};

/// A Device that reads `probe` (a hand position and a grasp button) and hands the haptic loop the
/// master's joints through a MasterHandMapping; commands go back to `probe` unchanged (the viewer
/// shows the torques). `probe` must outlive the adapter.
class MasterProbeDevice final : public Device {
 public:
  MasterProbeDevice(Device& probe, MasterHandMapping mapping)
      : probe_(probe), mapping_(std::move(mapping)) {}

  /// haptic path
  [[nodiscard]] DeviceInput read(double time_s) noexcept override {
    return mapping_.master_input(probe_.read(time_s));
  }
  /// haptic path
  void write(const DeviceCommand& command) noexcept override { probe_.write(command); }
  [[nodiscard]] const DeviceProfile& profile() const noexcept override { return probe_.profile(); }
  [[nodiscard]] DeviceStatus status() const noexcept override { return probe_.status(); }

 private:
  Device& probe_;
  MasterHandMapping mapping_;
};

}  // namespace hapsim
