// The real-time haptic loop (architecture.md#real-time, issue 5): a thread that runs one haptic
// cycle every period (1 ms) on an absolute-deadline clock — read the device, step the simulation,
// make the command safe, write the device, publish — plus a supervisor thread that takes over the
// device output when a cycle stalls.
//
// The haptic path allocates nothing, takes no lock and does no I/O: the simulation is a
// HapticClient whose step() is allocation-free (World::step), metrics go to fixed histograms
// and atomics, and the client publishes its snapshots through lock-free buffers
// (triple_buffer.h, spsc_ring.h) in after_cycle().
//
// Safety (architecture.md#force-and-safety): every command goes through ForceWatchdog (clamped to
// the device profile, NaN
// -> zero, ramp to zero when the device reports itself unhealthy). When no cycle completes for
// ramp.stale_timeout_s (the step overran, stalled, or the device read hung) the supervisor ramps
// the last good command to zero so that the output is zero by ramp.zero_by_s() (10 ms by
// default) after the last good cycle, and logs the event. When cycles resume, the force comes
// back over ramp.ramp_duration_s instead of jumping (no kick in the user's hand). The haptic
// thread does not rely on the supervisor for that: right before each write it measures the time
// since its own previous write (ResumeCeiling), and a gap beyond the grace cuts its force to what
// the supervisor's ramp would have left by then, so a whole-process freeze (SIGSTOP, a VM pause),
// after which either thread may run first, restarts the force from zero too. When the loop ends
// (max_cycles or stop()), the haptic thread fades its last force out over ramp.ramp_duration_s
// (no jolt when Ctrl-C ends a press) and its last write is a zero command.
#pragma once

#include "hapsim/device/device.h"
#include "hapsim/device/force_safety.h"
#include "hapsim/runtime/latency_histogram.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

namespace hapsim {

class ResumeCeiling;

struct HapticLoopOptions {
  double period_s = 0.001;
  /// Stop by itself after this many cycles (0: run until stop()).
  std::uint64_t max_cycles = 0;
  /// Ask for SCHED_FIFO (falls back quietly to normal scheduling when not permitted).
  bool realtime_priority = true;
  int fifo_priority = 80;
  /// With real-time priority: wake this long before each deadline and spin to it.
  double spin_s = 200e-6;
  /// A period longer than this counts as a missed deadline.
  double missed_period_s = 0.002;
  /// With realtime_priority: lock the process's memory where that is safe
  /// (try_lock_process_memory) and pre-fault the haptic thread's stack, so no cycle waits for a
  /// page fault.
  bool lock_memory = true;
  ForceRampParams ramp;
  /// How often the supervisor looks at the haptic thread's heartbeat.
  double supervisor_period_s = 0.001;
};

/// What one cycle did, handed to HapticClient::after_cycle on the haptic thread.
struct HapticCycle {
  std::uint64_t index = 0;
  /// Simulation time of the cycle: index · period (the clock of a scripted device).
  double time_s = 0.0;
  const DeviceInput* input = nullptr;
  /// The simulation's command (before safety), null when the step failed.
  const DeviceCommand* fresh = nullptr;
  /// What was written to the device (after clamp, ramp and resume).
  const DeviceCommand* output = nullptr;
  /// read + step + safety + write, microseconds.
  double cost_us = 0.0;
  /// Time since the previous cycle started, microseconds (0 for the first).
  double period_us = 0.0;
  bool healthy = true;
};

/// The simulation side of the loop (a World, a test double).
class HapticClient {
 public:
  virtual ~HapticClient() = default;
  /// haptic path: one step with this cycle's input; the command before safety. Must not
  /// allocate or block; an exception counts as a failed step (zero fresh command this cycle).
  virtual const DeviceCommand& step(const DeviceInput& input, double dt_s) = 0;
  /// haptic path, after the device write (outside the timed cost): publish snapshots.
  virtual void after_cycle(const HapticCycle& /*cycle*/) noexcept {}
  /// haptic path, right after step(): true when the force should come back from zero over the
  /// ramp time instead of at once (the simulation resumed after a pause or a reset, with the
  /// device possibly deep inside a body by now).
  virtual bool take_soft_start() noexcept { return false; }

 protected:
  HapticClient() = default;
  HapticClient(const HapticClient&) = default;
  HapticClient& operator=(const HapticClient&) = default;
  HapticClient(HapticClient&&) = default;
  HapticClient& operator=(HapticClient&&) = default;
};

/// Live figures, readable from any thread while the loop runs (a consistent-enough copy: each
/// field is read atomically on its own).
struct HapticLoopStatus {
  bool running = false;
  bool realtime_priority = false;
  /// The process's memory was locked (HapticLoopOptions::lock_memory).
  bool memory_locked = false;
  /// Page faults the haptic thread took after its first cycle (-1: unknown; counted when the
  /// loop ends): each one a cycle that waited for the kernel.
  long haptic_page_faults = -1;
  std::uint64_t cycles = 0;
  double elapsed_s = 0.0;
  /// cycles / elapsed wall time.
  double rate_hz = 0.0;
  /// |period − nominal period|, microseconds.
  LatencyPercentilesUs period_jitter_us;
  /// read + step + safety + write, microseconds.
  LatencyPercentilesUs cycle_cost_us;
  /// Periods longer than missed_period_s.
  std::uint64_t missed_deadlines = 0;
  /// Times the supervisor found the haptic thread stalled and ramped the force down.
  std::uint64_t stall_events = 0;
  /// Cycles whose output a ramp capped (the watchdog's, for an unhealthy device or failed steps,
  /// or the timing ceiling's), whether or not there was force to cap.
  std::uint64_t ramp_cycles = 0;
  /// Of those, the cycles capped for lateness alone, with the device healthy and the step fine:
  /// the supervisor's stall ramp, the haptic thread's own gap cut, the ramp back after either
  /// (and the rare soft start after a reset or unpause, or the ramp back after a device
  /// recovered). Many of them mean the build or the machine cannot keep the rate.
  std::uint64_t late_ramp_cycles = 0;
  /// Transitions of the device from healthy to not.
  std::uint64_t device_health_losses = 0;
  /// Steps that threw (each yields zero fresh force).
  std::uint64_t failed_steps = 0;
  /// Cycles that found more than the grace (ramp.stale_timeout_s) since the haptic thread's own
  /// previous write and cut their force for it (a whole-process freeze, a long preemption):
  /// counted whether or not the supervisor saw the gap too.
  std::uint64_t resume_gaps = 0;
  std::uint64_t clamped_cycles = 0;
  std::uint64_t nonfinite_commands = 0;
  double last_output_force_n = 0.0;
};

class HapticLoop {
 public:
  /// `device` and `client` must outlive the loop. Throws hapsim::Error on bad options.
  HapticLoop(Device& device, HapticClient& client, HapticLoopOptions options = {});
  ~HapticLoop();
  HapticLoop(const HapticLoop&) = delete;
  HapticLoop& operator=(const HapticLoop&) = delete;
  HapticLoop(HapticLoop&&) = delete;
  HapticLoop& operator=(HapticLoop&&) = delete;

  /// Starts the haptic and supervisor threads. Throws if already started.
  void start();
  /// Asks the haptic thread to stop after its current cycle (any thread, non-blocking).
  void request_stop() noexcept;
  /// Stops, joins both threads and writes a zero command to the device. Idempotent.
  void stop();
  /// Blocks until the loop stops by itself (max_cycles) or stop() is called elsewhere, then
  /// joins as stop() does.
  void wait();

  [[nodiscard]] bool running() const noexcept { return running_.load(std::memory_order_acquire); }
  [[nodiscard]] HapticLoopStatus status() const noexcept;
  [[nodiscard]] const HapticLoopOptions& options() const { return options_; }

 private:
  struct Shared;
  void haptic_thread_main() noexcept;
  void supervisor_thread_main() noexcept;
  /// Writes `command` unless the other thread is writing right now (never waits); true if
  /// written.
  bool try_write(const DeviceCommand& command) noexcept;
  /// The haptic thread's write (with `resume`): also applies a supervisor ceiling lowered since
  /// `resume` was updated, scaling `command` (left as written) and lowering `resume`.
  bool try_write(DeviceCommand& command, ResumeCeiling* resume) noexcept;

  Device& device_;
  HapticClient& client_;
  HapticLoopOptions options_;
  std::unique_ptr<Shared> shared_;
  LatencyHistogram jitter_us_;
  LatencyHistogram cost_us_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  std::thread haptic_thread_;
  std::thread supervisor_thread_;
  bool started_ = false;
};

/// Scales every force and torque of `command` by `gain` in [0, 1]. haptic path
[[nodiscard]] DeviceCommand scaled_command(const DeviceCommand& command, double gain) noexcept;

}  // namespace hapsim
