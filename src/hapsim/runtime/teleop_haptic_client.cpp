#include "hapsim/runtime/teleop_haptic_client.h"

namespace hapsim {

TeleopHapticClient::TeleopHapticClient(World& world, TeleopHapticClientOptions options)
    : world_(world), options_(options) {
  if (options_.publish_snapshots) {
    snapshots_ = std::make_unique<TripleBuffer<TeleopSnapshot>>(make_teleop_snapshot(world_));
  }
  if (options_.record_capacity > 0) {
    records_ = std::make_unique<SpscRing<TeleopCycleRecord>>(options_.record_capacity);
  }
}

// haptic path
const DeviceCommand& TeleopHapticClient::step(const DeviceInput& input, double dt_s) {
  const bool paused = paused_.load(std::memory_order_relaxed);
  if (paused != was_paused_) {
    was_paused_ = paused;
    soft_start_ = !paused;  // back from a pause: the master's torques come back gradually
  }
  stepped_ = false;
  if (paused) {
    return zero_command_;
  }
  stepped_ = true;
  const DeviceCommand& command = world_.step(input, dt_s).command;
  steps_.store(steps_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  return command;
}

// haptic path
void TeleopHapticClient::after_cycle(const HapticCycle& cycle) noexcept {
  if (records_ && stepped_) {
    scratch_record_.result = world_.rig()->result;
    scratch_record_.output = cycle.output != nullptr ? *cycle.output : zero_command_;
    scratch_record_.cost_us = cycle.cost_us;
    if (!records_->push(scratch_record_)) {
      dropped_records_.store(dropped_records_.load(std::memory_order_relaxed) + 1,
                             std::memory_order_relaxed);
    }
  }
  if (!snapshots_) {
    return;
  }
  TeleopSnapshot& s = snapshots_->write_slot();
  s.cycle = cycle.index;
  s.time_s = cycle.time_s;
  if (cycle.input != nullptr) {
    s.input = *cycle.input;
  }
  s.output = cycle.output != nullptr ? *cycle.output : zero_command_;
  fill_teleop_snapshot(s, world_);
  snapshots_->publish();
}

}  // namespace hapsim
