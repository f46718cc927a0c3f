// The haptic loop's client for a World (000 on the real-time loop): each cycle steps the
// world with the master's input and returns the torques for the master's motors, then publishes
// the newest TeleopSnapshot for the viewer through a triple buffer. Every buffer is sized at
// construction: after_cycle() allocates nothing (haptic path). Optionally every cycle's result
// also goes through a ring to a consumer (hapsim run --realtime's bookkeeping).
#pragma once

#include "hapsim/core/spsc_ring.h"
#include "hapsim/core/triple_buffer.h"
#include "hapsim/runtime/haptic_loop.h"
#include "hapsim/runtime/teleop_snapshot.h"

#include <atomic>
#include <memory>

namespace hapsim {

struct TeleopHapticClientOptions {
  /// Publish a viewer snapshot every cycle (true) or not at all (a headless run).
  bool publish_snapshots = true;
  /// Capacity of the ring of every cycle's record (0: none), for a real-time run's bookkeeping.
  std::size_t record_capacity = 0;
};

/// One cycle of a teleoperation world, fixed-size, for the records ring.
struct TeleopCycleRecord {
  TeleopStepResult result;
  /// What the master's motors were sent (after safety).
  DeviceCommand output;
  double cost_us = 0.0;
};

class TeleopHapticClient final : public HapticClient {
 public:
  /// `world` must outlive the client; its description gives every size.
  explicit TeleopHapticClient(World& world, TeleopHapticClientOptions options = {});

  /// world.step(input, dt).command, or zero while paused. haptic path
  const DeviceCommand& step(const DeviceInput& input, double dt_s) override;
  /// Publishes the snapshot: the cycle's input, the command after safety, the world's state.
  /// haptic path
  void after_cycle(const HapticCycle& cycle) noexcept override;

  /// Reader side of the snapshots (one reader thread), null when not publishing.
  [[nodiscard]] TripleBuffer<TeleopSnapshot>* snapshots() { return snapshots_.get(); }
  /// Consumer side of the records (one consumer thread), null when not recording.
  [[nodiscard]] SpscRing<TeleopCycleRecord>* records() { return records_.get(); }
  /// Records that did not fit in the ring (the consumer fell behind).
  [[nodiscard]] std::uint64_t dropped_records() const {
    return dropped_records_.load(std::memory_order_relaxed);
  }

  /// Any thread: stop stepping the world (the slave and the ball freeze, zero torque) or go on.
  /// (The viewer resets by rebuilding the world, so there is no request_reset() here yet.)
  void set_paused(bool paused) { paused_.store(paused, std::memory_order_relaxed); }
  /// haptic path: true once after a pause ends.
  bool take_soft_start() noexcept override {
    const bool soft = soft_start_;
    soft_start_ = false;
    return soft;
  }
  [[nodiscard]] bool paused() const { return paused_.load(std::memory_order_relaxed); }

  /// Cycles that stepped the world (read from any thread).
  [[nodiscard]] std::uint64_t steps() const { return steps_.load(std::memory_order_relaxed); }

 private:
  World& world_;
  TeleopHapticClientOptions options_;
  DeviceCommand zero_command_;
  std::unique_ptr<TripleBuffer<TeleopSnapshot>> snapshots_;
  std::unique_ptr<SpscRing<TeleopCycleRecord>> records_;
  TeleopCycleRecord scratch_record_;
  bool stepped_ = false;  // this cycle stepped the world
  std::atomic<std::uint64_t> dropped_records_{0};
  std::atomic<bool> paused_{false};
  bool was_paused_ = false;  // haptic thread only
  bool soft_start_ = false;
  std::atomic<std::uint64_t> steps_{0};
};

}  // namespace hapsim
