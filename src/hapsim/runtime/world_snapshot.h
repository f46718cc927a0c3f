// What the viewer (and later the network) sees of a running World: the newest cycle's tools,
// contacts, forces and the deformed surfaces, published by the haptic thread through a triple
// buffer (world_haptic_client.h). Sized once for a world, so publishing never allocates.
#pragma once

#include "hapsim/runtime/teleop_snapshot.h"
#include "hapsim/world/world.h"

#include <cstdint>
#include <vector>

namespace hapsim {

struct WorldSnapshot {
  std::uint64_t cycle = 0;
  /// The loop's clock (runs on while paused).
  double time_s = 0.0;
  /// The world's own clock: stands still while paused, back to 0 after a reset.
  double world_time_s = 0.0;
  DeviceInput input;
  /// What the device was sent (after safety).
  DeviceCommand output;
  /// One per tool.
  std::vector<ToolState> tools;
  /// Force each tool renders on the device, newtons (its finger actuator or its share of the
  /// tip force, after safety).
  std::vector<double> tool_force_n;
  /// This cycle's contacts: the first contact_count entries.
  std::vector<WorldContact> contacts;
  std::size_t contact_count = 0;
  /// Per flat segment (World::flat_segment): the deformed vertex positions in the body frame,
  /// x,y,z per vertex as float (what a renderer uploads); empty for rigid segments.
  std::vector<std::vector<float>> positions_body;
  /// Per flat segment: largest deflection right now, metres.
  std::vector<double> deflection_m;
  /// Per flat segment: bumped whenever positions_body changed, so a reader re-uploads only then.
  /// A sheet's grid (its surface, imprints included) is published there too, every cycle.
  std::vector<std::uint64_t> positions_version;
  /// Per body: where it is now (dynamic bodies move).
  std::vector<Iso3> body_poses_world;
  /// A glove world's hand: its pose and finger angles (World::hand_reading).
  GloveReading hand;
  /// The teleoperation rig (slave, gripper, ball, sheet, master), when the world has one.
  std::optional<TeleopSnapshot> teleop;
};

/// A snapshot sized for `world`, holding its current state (rest surfaces at start).
[[nodiscard]] WorldSnapshot make_world_snapshot(const World& world);

}  // namespace hapsim
