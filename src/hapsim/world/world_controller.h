// A controller attached to ordinary bodies of the world (architecture.md#controllers): iMSTK's
// "the device client provides quantities, the controller decides what to do with them". The place
// stage hands it the device's input before the tools are placed, and it moves the kinematic
// bodies it drives (their pose and velocity in WorldState::bodies) and may put the tools where
// its own mechanism holds them; the safety stage asks it for the device's command from this
// step's contacts; after the stages it observes the step's result, read-only, for its reports.
// The stages name none of its bodies: a controller is code above the world (rig/ is one).
#pragma once

#include "hapsim/core/device_io.h"

#include <memory>
#include <string_view>

namespace hapsim {

class ContentFingerprint;
class WorldModel;
struct StepResult;
struct WorldDescription;
struct WorldState;

/// A controller's per-world state, owned by the WorldState it was made for.
class ControllerState {
 public:
  ControllerState() = default;
  virtual ~ControllerState() = default;
  ControllerState(const ControllerState&) = delete;
  ControllerState& operator=(const ControllerState&) = delete;
  ControllerState(ControllerState&&) = delete;
  ControllerState& operator=(ControllerState&&) = delete;

  /// Back to the start (World::reset). haptic path: no allocation (a reset asked for from the
  /// viewer runs on the haptic thread).
  virtual void reset() noexcept = 0;
  /// Place stage, before the tools: move the bodies it drives for `input`. It may replace
  /// `tool_input`, which the place stage then places device 0's tools from (a robot's tool
  /// follows the robot, not the hand); it starts as `input`. haptic path
  virtual void place(const WorldModel& model, WorldState& state, const DeviceInput& input,
                     DeviceInput& tool_input, double dt_s) noexcept = 0;
  /// Safety stage, after the tools' forces: the device's command. It starts as the tools' own
  /// (finger forces and the tip force); a controller that drives the device another way (a
  /// master arm's joint torques) writes its own. haptic path
  virtual void command(const WorldModel& model, const WorldState& state,
                       DeviceCommand& command) noexcept = 0;
  /// After the stages: the step's result, read-only, for the controller's reports (nothing it
  /// does here changes the step). haptic path
  virtual void observe(const WorldModel& model, const StepResult& result) noexcept = 0;
};

/// A controller's description and read-only model, shared by every world built from the
/// description that holds it (WorldDescription::controller).
class WorldController {
 public:
  WorldController() = default;
  virtual ~WorldController() = default;
  WorldController(const WorldController&) = delete;
  WorldController& operator=(const WorldController&) = delete;
  WorldController(WorldController&&) = delete;
  WorldController& operator=(WorldController&&) = delete;

  /// What it is, for messages ("rig").
  [[nodiscard]] virtual std::string_view kind() const noexcept = 0;
  /// Checked when the model is built: throws hapsim::Error naming what in `world` it cannot
  /// drive (a body index out of range, a body of the wrong kind).
  virtual void check(const WorldDescription& world) const = 0;
  /// Adds to the world's content hash what makes its worlds step differently (recordings carry
  /// the hash: a replay refuses a world that would not step the same).
  virtual void fingerprint(ContentFingerprint& h) const = 0;
  /// Its per-world state, sized for `model` (a WorldState holds it). Throws hapsim::Error.
  [[nodiscard]] virtual std::unique_ptr<ControllerState> make_state(
      const WorldModel& model) const = 0;
};

}  // namespace hapsim
