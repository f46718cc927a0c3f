// Everything one haptic cycle of a World produced that the run's bookkeeping and the recorder
// need, as fixed-size data: the haptic thread copies it into an SPSC ring (no allocation) and
// the main thread accounts for it (run_session) and records it, at its own pace.
#pragma once

#include "hapsim/device/recording.h"
#include "hapsim/rig/rig_step_result.h"
#include "hapsim/world/world.h"

#include <array>
#include <cstdint>

namespace hapsim {

inline constexpr int kMaxCycleTools = kMaxTools;
inline constexpr int kMaxCycleContacts = 64;
/// Dynamic bodies and sheets a cycle record follows (the first ones of the world).
inline constexpr int kMaxCycleDynamicBodies = 8;
inline constexpr int kMaxCycleSheets = 4;

struct CycleRecord {
  std::uint64_t cycle = 0;
  double time_s = 0.0;
  DeviceInput input;
  /// The world's command, before the safety layer.
  DeviceCommand world_command;
  /// What was written to the device (after clamp and ramp): the run's figures. Not recorded: the
  /// real-time loop's stall and resume ramps depend on wall-clock time, which a replay cannot redo.
  DeviceCommand output;
  std::array<ToolState, kMaxCycleTools> tools{};
  std::int32_t tool_count = 0;
  std::array<WorldContact, kMaxCycleContacts> contacts{};
  std::int32_t contact_count = 0;
  /// Contacts the world could not report plus those beyond kMaxCycleContacts.
  std::int32_t dropped_contacts = 0;
  /// Tools pulled through a penalty segment this cycle (StepResult::penalty_pop_throughs).
  std::int32_t penalty_pop_throughs = 0;
  /// The first dynamic bodies (in body order): where their body frames are
  /// and, as a bit per body index (< 64), which bodies each touches this cycle.
  std::array<Vec3, kMaxCycleDynamicBodies> dynamic_p_world{};
  std::array<std::uint64_t, kMaxCycleDynamicBodies> dynamic_touching{};
  std::int32_t dynamic_count = 0;
  /// The first sheets (in flat segment order): their deepest dent, metres.
  std::array<double, kMaxCycleSheets> sheet_depth_m{};
  std::int32_t sheet_count = 0;
  /// The teleoperation rig's step (when the world has a rig: has_teleop).
  bool has_teleop = false;
  TeleopStepResult teleop;
  /// What the step cost, us: World::step in the real-time loop (never the device's read, which
  /// for a served world is the lockstep wait); the inline run's read, step, safety and write.
  double cost_us = 0.0;
};

/// haptic path: fills `record` from a step's result (no allocation).
void fill_cycle_record(CycleRecord& record, std::uint64_t cycle, const DeviceInput& input,
                       const StepResult& result, const DeviceCommand& output,
                       double cost_us) noexcept;

/// The recorder's frame of a cycle (its first kMaxRecordedContacts contacts). Its command is the
/// deterministic part of the safety layer, the world's command clamped to `profile`
/// (clamp_command): what a replay recomputes from the recorded inputs, whatever the loop's ramps
/// did to the output at the time (they depend on wall-clock time; CycleRecord::output has them).
[[nodiscard]] RecordedFrame to_recorded_frame(const CycleRecord& record,
                                              const DeviceProfile& profile) noexcept;

}  // namespace hapsim
