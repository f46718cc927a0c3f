// The haptic loop's client for a World (architecture.md#real-time): each cycle steps the world,
// then publishes
// - the newest snapshot for the viewer through a triple buffer (deformed vertices copied by
//   delta: only the ones that moved since that slot was last written, so the copy costs about
//   what the step's own deformation update did), and
// - every cycle's record through an SPSC ring to the run's bookkeeping and the recorder.
// All buffers are sized at construction: after_cycle() allocates nothing (haptic path).
#pragma once

#include "hapsim/core/spsc_ring.h"
#include "hapsim/core/triple_buffer.h"
#include "hapsim/runtime/cycle_record.h"
#include "hapsim/runtime/haptic_loop.h"
#include "hapsim/runtime/world_snapshot.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace hapsim {

/// Something that serves the running world from the haptic thread (`hapsim serve` publishes each
/// step's local contact models from it). Both calls are haptic path: no allocation, no blocking.
class WorldCycleObserver {
 public:
  virtual ~WorldCycleObserver() = default;
  /// Before the world steps with this cycle's input (may e.g. make it forget the tools' motion
  /// when the input's source changed).
  virtual void before_step(World& /*world*/) noexcept {}
  /// After the step and the device write: the world holds this cycle's state.
  virtual void after_step(const World& world, const HapticCycle& cycle) noexcept = 0;
  /// After a cycle that did not step (the client is paused: the device got zero force).
  virtual void after_paused_cycle(const World& /*world*/, const HapticCycle& /*cycle*/) noexcept {}

 protected:
  WorldCycleObserver() = default;
  WorldCycleObserver(const WorldCycleObserver&) = default;
  WorldCycleObserver& operator=(const WorldCycleObserver&) = default;
  WorldCycleObserver(WorldCycleObserver&&) = default;
  WorldCycleObserver& operator=(WorldCycleObserver&&) = default;
};

struct WorldHapticClientOptions {
  /// Publish a viewer snapshot every cycle (true) or not at all (a headless run).
  bool publish_snapshots = true;
  /// Capacity of the record ring in cycles (0: no records). 2048 gives the consumer 2 s of slack.
  std::size_t record_capacity = 0;
  /// Called around every step that is taken, and after every paused cycle. Not owned; may be
  /// null.
  WorldCycleObserver* observer = nullptr;
};

class WorldHapticClient final : public HapticClient {
 public:
  /// `world` must outlive the client; its description gives every size.
  explicit WorldHapticClient(World& world, WorldHapticClientOptions options = {});

  /// haptic path
  const DeviceCommand& step(const DeviceInput& input, double dt_s) override;
  /// haptic path
  void after_cycle(const HapticCycle& cycle) noexcept override;
  /// haptic path: true once after a pause ends or a reset.
  bool take_soft_start() noexcept override {
    const bool soft = soft_start_;
    soft_start_ = false;
    return soft;
  }

  /// Reader side of the snapshots (one reader thread), null when not publishing.
  [[nodiscard]] TripleBuffer<WorldSnapshot>* snapshots() { return snapshots_.get(); }
  /// Consumer side of the records (one consumer thread), null when not recording.
  [[nodiscard]] SpscRing<CycleRecord>* records() { return records_.get(); }
  /// Records that did not fit in the ring (the consumer fell behind).
  [[nodiscard]] std::uint64_t dropped_records() const {
    return dropped_records_.load(std::memory_order_relaxed);
  }
  /// Per flat segment: the largest deflection seen in any cycle. Read after the loop stopped.
  [[nodiscard]] const std::vector<double>& max_deflection_m() const { return max_deflection_m_; }

  /// Any thread: stop stepping the world (tools hold still, zero force) or go on.
  void set_paused(bool paused) { paused_.store(paused, std::memory_order_relaxed); }
  [[nodiscard]] bool paused() const { return paused_.load(std::memory_order_relaxed); }
  /// Any thread: the haptic thread resets the world at its next cycle.
  void request_reset() { reset_requested_.store(true, std::memory_order_release); }
  /// One other thread (the viewer): new contact parameters for a material, applied by the haptic
  /// thread before its next step (World::set_material_contact). False when the queue is full.
  bool request_material(std::uint32_t material, const ContactMaterial& contact) {
    return material_changes_.push({material, contact});
  }
  /// Material changes the world refused (bad values), counted on the haptic thread.
  [[nodiscard]] std::uint64_t refused_material_changes() const {
    return refused_material_changes_.load(std::memory_order_relaxed);
  }

 private:
  struct DeformableSegment {
    std::size_t flat = 0;
    const VertexDeflection* deflection = nullptr;
    // Per triple-buffer slot: vertices moved since that slot was last written; per vertex, bit k
    // set when it is listed for slot k (one byte to test for the three slots).
    std::array<std::vector<std::uint32_t>, 3> pending;
    std::vector<std::uint8_t> owed;
    std::uint64_t changes = 0;  // steps that moved a vertex: the published version
  };

  void publish_snapshot(const HapticCycle& cycle) noexcept;

  World& world_;
  WorldHapticClientOptions options_;
  const StepResult* last_result_ = nullptr;
  bool stepped_ = false;     // this cycle stepped the world (not paused)
  bool was_paused_ = false;  // haptic thread's view of the last cycle
  bool soft_start_ = false;
  // Cycles that stepped the world so far: the records' numbering (haptic thread).
  std::uint64_t recorded_cycles_ = 0;
  // World::step alone, this cycle: a record's cost (the loop's cycle also holds the device's read,
  // which for a served world is the lockstep wait for the device host's state).
  double step_cost_us_ = 0.0;
  DeviceCommand zero_command_;
  std::size_t carried_tool_ = static_cast<std::size_t>(-1);  // the tool a rig carries, if any
  std::unique_ptr<TripleBuffer<WorldSnapshot>> snapshots_;
  std::unique_ptr<SpscRing<CycleRecord>> records_;
  CycleRecord scratch_record_;
  std::vector<DeformableSegment> deformable_;
  /// Sheets: (flat segment, body); their small grids are published whole every cycle.
  std::vector<std::pair<std::size_t, std::size_t>> sheets_;
  std::uint64_t sheet_version_ = 0;
  std::vector<double> max_deflection_m_;
  std::atomic<std::uint64_t> dropped_records_{0};
  struct MaterialChange {
    std::uint32_t material = 0;
    ContactMaterial contact;
  };
  SpscRing<MaterialChange> material_changes_{64};
  std::atomic<std::uint64_t> refused_material_changes_{0};
  std::atomic<bool> paused_{false};
  std::atomic<bool> reset_requested_{false};
};

}  // namespace hapsim
