#include "hapsim/runtime/cycle_record.h"

#include "hapsim/device/force_safety.h"
#include "hapsim/rig/rig_controller.h"

#include <algorithm>

namespace hapsim {

void fill_cycle_record(CycleRecord& record, std::uint64_t cycle, const DeviceInput& input,
                       const StepResult& result, const DeviceCommand& output,
                       double cost_us) noexcept {
  record.cycle = cycle;
  record.time_s = input.time_s;
  record.input = input;
  record.world_command = result.command;
  record.output = output;
  const std::size_t tools = std::min<std::size_t>(result.tools.size(), kMaxCycleTools);
  std::copy_n(result.tools.begin(), tools, record.tools.begin());
  record.tool_count = static_cast<std::int32_t>(tools);
  const std::size_t contacts = std::min<std::size_t>(result.contacts.size(), kMaxCycleContacts);
  std::copy_n(result.contacts.begin(), contacts, record.contacts.begin());
  record.contact_count = static_cast<std::int32_t>(contacts);
  record.dropped_contacts = std::max(0, result.dropped_contacts) +
                            static_cast<std::int32_t>(result.contacts.size() - contacts);
  record.penalty_pop_throughs = result.penalty_pop_throughs;
  record.dynamic_count = 0;
  for (std::size_t b = 0; b < result.bodies.size(); ++b) {
    if (result.bodies[b].dynamic && record.dynamic_count < kMaxCycleDynamicBodies) {
      const auto i = static_cast<std::size_t>(record.dynamic_count++);
      record.dynamic_p_world[i] = result.bodies[b].X_world_body.translation();
      record.dynamic_touching[i] = 0;
      for (const BodyContact& c : result.body_contacts) {
        if (c.body == BodyIndex{b} && c.other_body.valid() && c.other_body.value < 64) {
          record.dynamic_touching[i] |= std::uint64_t{1} << c.other_body.value;
        }
      }
    }
  }
  record.sheet_count = 0;
  for (const double depth : result.sheet_depth_m) {
    if (record.sheet_count < kMaxCycleSheets) {
      record.sheet_depth_m[static_cast<std::size_t>(record.sheet_count++)] = depth;
    }
  }
  const TeleopStepResult* rig = rig_result(result);
  record.has_teleop = rig != nullptr;
  if (rig != nullptr) {
    record.teleop = *rig;
  }
  record.cost_us = cost_us;
}

RecordedFrame to_recorded_frame(const CycleRecord& record, const DeviceProfile& profile) noexcept {
  RecordedFrame frame;
  frame.cycle_index = record.cycle;
  frame.input = record.input;
  frame.command = clamp_command(record.world_command, profile);
  const int n = std::min(record.contact_count, kMaxRecordedContacts);
  frame.contact_count = n;
  for (int i = 0; i < n; ++i) {
    const WorldContact& c = record.contacts[static_cast<std::size_t>(i)];
    RecordedContact& r = frame.contacts[static_cast<std::size_t>(i)];
    // The recording's fields stay plain integers (its on-disk format); segment is body-local.
    r.tool_index = c.tool.value;
    r.body_index = c.body.value;
    r.segment_index = c.segment.value;
    r.point_world = c.point_world;
    r.normal_world = c.normal_world;
    r.depth_m = c.depth_m;
    r.force_n = c.force_n;
  }
  return frame;
}

}  // namespace hapsim
