#include "hapsim/runtime/haptic_loop.h"

#include "hapsim/core/error.h"
#include "hapsim/core/triple_buffer.h"
#include "hapsim/device/resume_ceiling.h"
#include "hapsim/runtime/deadline_clock.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

namespace hapsim {

DeviceCommand scaled_command(const DeviceCommand& command, double gain) noexcept {
  const double g = std::isfinite(gain) ? std::clamp(gain, 0.0, 1.0) : 0.0;
  DeviceCommand out = command;
  out.force_world_n *= g;
  for (double& f : out.finger_force_n) {
    f *= g;
  }
  for (double& t : out.joint_torque_nm) {
    t *= g;
  }
  return out;
}

// What the haptic thread last wrote, and the share of its commanded force that carried (its
// ceiling): a stall during a ramp must go on down from the ramped force, not from the full one.
struct WrittenCommand {
  DeviceCommand command;
  double ceiling = 1.0;
};

struct HapticLoop::Shared {
  explicit Shared(const DeviceProfile& profile, const ForceRampParams& ramp)
      : watchdog(profile, ramp), last_written(WrittenCommand{}) {}

  ForceWatchdog watchdog;                     // haptic thread only
  TripleBuffer<WrittenCommand> last_written;  // haptic thread -> supervisor: the ramp's base
  std::atomic_flag output_busy = ATOMIC_FLAG_INIT;
  std::atomic<std::int64_t> start_ns{0};
  std::atomic<std::int64_t> end_ns{0};
  std::atomic<std::int64_t> heartbeat_ns{0};  // end of the last completed cycle
  // Ceiling on the haptic thread's output: the lowest gain the supervisor wrote (lowered before
  // each write), until the haptic thread takes it.
  std::atomic<double> supervisor_gain{1.0};
  std::atomic<bool> device_healthy{true};
  std::atomic<bool> realtime_priority{false};
  std::atomic<bool> memory_locked{false};
  std::atomic<long> haptic_page_faults{-1};
  std::atomic<std::uint64_t> cycles{0};
  std::atomic<std::uint64_t> missed{0};
  std::atomic<std::uint64_t> stall_events{0};
  std::atomic<std::uint64_t> ramp_cycles{0};
  std::atomic<std::uint64_t> late_ramp_cycles{0};  // of those, capped for lateness alone
  std::atomic<std::uint64_t> health_losses{0};
  std::atomic<std::uint64_t> failed_steps{0};
  std::atomic<std::uint64_t> resume_gaps{0};  // haptic thread: gaps its ceiling cut for
  std::atomic<std::int64_t> last_gap_ns{0};   // the latest such gap (stored before the count)
  std::atomic<double> last_output_force_n{0.0};
};

namespace {

double command_magnitude_n(const DeviceCommand& c) {
  double m = c.force_world_n.norm();
  for (int f = 0; f < c.finger_count && f < kMaxFingers; ++f) {
    m = std::max(m, c.finger_force_n[static_cast<std::size_t>(f)]);
  }
  return m;
}

// Lowers `gain` to `to` unless it is lower already (the haptic thread may reset it at any time).
void lower_gain(std::atomic<double>& gain, double to) noexcept {
  double current = gain.load();
  while (to < current && !gain.compare_exchange_weak(current, to)) {
  }
}

// Single-writer counter increment (no read-modify-write needed with one writer).
void bump(std::atomic<std::uint64_t>& counter) noexcept {
  counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

}  // namespace

HapticLoop::HapticLoop(Device& device, HapticClient& client, HapticLoopOptions options)
    : device_(device), client_(client), options_(options) {
  if (!(options_.period_s > 0.0) || !(options_.period_s <= 0.1)) {
    throw Error("haptic loop",
                "period must be in (0, 0.1] s, got " + std::to_string(options_.period_s));
  }
  if (!(options_.supervisor_period_s > 0.0) || !(options_.supervisor_period_s <= 0.1)) {
    throw Error("haptic loop", "supervisor period must be in (0, 0.1] s");
  }
  if (!(options_.ramp.stale_timeout_s >= 0.0) || !(options_.ramp.ramp_duration_s >= 0.0) ||
      !std::isfinite(options_.ramp.zero_by_s())) {
    throw Error("haptic loop", "ramp times must be finite and >= 0");
  }
  shared_ = std::make_unique<Shared>(device_.profile(), options_.ramp);
}

HapticLoop::~HapticLoop() {
  stop();
}

void HapticLoop::start() {
  if (started_) {
    throw Error("haptic loop", "already started (a loop runs once)");
  }
  started_ = true;
  if (options_.realtime_priority && options_.lock_memory) {
    shared_->memory_locked.store(try_lock_process_memory());
  }
  stop_requested_.store(false);
  shared_->start_ns.store(monotonic_ns());
  shared_->heartbeat_ns.store(shared_->start_ns.load());
  running_.store(true, std::memory_order_release);
  haptic_thread_ = std::thread([this] { haptic_thread_main(); });
  supervisor_thread_ = std::thread([this] { supervisor_thread_main(); });
}

void HapticLoop::request_stop() noexcept {
  stop_requested_.store(true, std::memory_order_release);
}

void HapticLoop::stop() {
  request_stop();
  wait();
}

void HapticLoop::wait() {
  if (haptic_thread_.joinable()) {
    haptic_thread_.join();
  }
  if (supervisor_thread_.joinable()) {
    supervisor_thread_.join();
  }
  if (started_) {
    // Leave the device pushing nothing.
    DeviceCommand zero;
    zero.finger_count = device_.profile().finger_count;
    device_.write(zero);
    shared_->last_output_force_n.store(0.0);
  }
}

bool HapticLoop::try_write(const DeviceCommand& command) noexcept {
  DeviceCommand copy = command;
  return try_write(copy, nullptr);
}

// haptic path (with `resume`)
bool HapticLoop::try_write(DeviceCommand& command, ResumeCeiling* resume) noexcept {
  if (shared_->output_busy.test_and_set(std::memory_order_acquire)) {
    return false;  // the other thread is writing: its value stands for this cycle
  }
  if (resume != nullptr) {
    // The haptic thread took its ceiling before the write; a supervisor write that landed in
    // between lowered supervisor_gain first (lower_gain, then its write): honour it now, or the
    // device would see the supervisor's lowered force and then this one above it.
    const double late = shared_->supervisor_gain.exchange(1.0);
    const double share = resume->ceiling();
    if (late < share) {
      command = scaled_command(command, share > 0.0 ? late / share : 0.0);
      resume->lower_to(late);
    }
  }
  device_.write(command);
  shared_->output_busy.clear(std::memory_order_release);
  shared_->last_output_force_n.store(command_magnitude_n(command), std::memory_order_relaxed);
  return true;
}

// haptic path (the loop body): no allocation, no lock, no I/O.
void HapticLoop::haptic_thread_main() noexcept {
  Shared& s = *shared_;
  const bool realtime =
      options_.realtime_priority && try_set_realtime_priority(options_.fifo_priority);
  s.realtime_priority.store(realtime);
  if (options_.realtime_priority && options_.lock_memory) {
    prefault_stack(256 * 1024);
  }
  long faults_after_first_cycle = -1;
  const auto period_ns = static_cast<std::int64_t>(std::llround(options_.period_s * 1e9));
  DeadlineClock clock(
      period_ns, realtime ? static_cast<std::int64_t>(std::llround(options_.spin_s * 1e9)) : 0);
  const double nominal_us = options_.period_s * 1e6;
  const double missed_us = options_.missed_period_s * 1e6;
  // The haptic thread's own ceiling while force comes back: it also measures the gap since its
  // previous write itself, so a whole-process freeze is ramped whichever thread resumes first.
  ResumeCeiling resume(options_.period_s, options_.ramp);
  bool was_healthy = true;
  std::int64_t previous_wake_ns = 0;
  const std::int64_t start_ns = s.start_ns.load();
  DeviceCommand last_out;  // the haptic thread's newest write: where the end's fade starts
  last_out.finger_count = device_.profile().finger_count;
  clock.start();

  for (std::uint64_t i = 0; !stop_requested_.load(std::memory_order_acquire) &&
                            (options_.max_cycles == 0 || i < options_.max_cycles);
       ++i) {
    const std::int64_t wake_ns = clock.wait_next();
    if (i == 1) {
      faults_after_first_cycle = thread_page_faults();
    }
    double period_us = 0.0;
    if (i > 0) {
      period_us = 1e-3 * static_cast<double>(wake_ns - previous_wake_ns);
      jitter_us_.record_us(std::abs(period_us - nominal_us));
      if (period_us > missed_us) {
        bump(s.missed);
      }
    }
    previous_wake_ns = wake_ns;
    const double t_s = static_cast<double>(i) * options_.period_s;

    // The timed cycle: read, step, safety, write.
    const std::int64_t c0 = monotonic_ns();
    const DeviceInput input = device_.read(t_s);
    const bool healthy = input.healthy && device_.status().health == DeviceHealth::kConnected;
    const DeviceCommand* fresh = nullptr;
    try {
      fresh = &client_.step(input, options_.period_s);
    } catch (...) {
      bump(s.failed_steps);  // no fresh force this cycle: the watchdog holds, then ramps
    }
    const double now_s = 1e-9 * static_cast<double>(c0 - start_ns);
    DeviceCommand out = s.watchdog.update(now_s, fresh, healthy);
    const bool soft_start = client_.take_soft_start();
    if (healthy != was_healthy) {
      if (!healthy) {
        bump(s.health_losses);
      }
      s.device_healthy.store(healthy, std::memory_order_relaxed);
      was_healthy = healthy;
    }
    // The ceiling is taken as late as possible before the write, so that a freeze anywhere in the
    // cycle (the sleep, the read, the step) shows as a gap since the previous write.
    const std::int64_t write_ns = monotonic_ns();
    const double ceiling_of_last_write = resume.ceiling();
    const double ceiling = resume.update(1e-9 * static_cast<double>(write_ns - start_ns),
                                         s.supervisor_gain.exchange(1.0), soft_start);
    if (resume.gap_cut()) {
      s.last_gap_ns.store(std::llround(resume.last_gap_s() * 1e9), std::memory_order_relaxed);
      s.resume_gaps.store(resume.gaps(), std::memory_order_release);
    }
    if (s.watchdog.ramping()) {
      // Already the last good command scaled by the watchdog's gain: at most the ceiling, and
      // force comes back from the lower of the two. A resume ramp under way stops rising here
      // (the device was lost or the steps fail: from the last write the force only falls; a
      // loss during the ramp back after a stall once wrote 1.312 N after 1.307 N).
      const double watchdog_gain = s.watchdog.output_gain();
      const double cap = std::min(ceiling, ceiling_of_last_write);
      if (cap < watchdog_gain) {
        out = scaled_command(out, cap / watchdog_gain);
      }
      resume.lower_to(std::min(watchdog_gain, cap));
      bump(s.ramp_cycles);
    } else if (ceiling < 1.0) {
      // Capped for lateness alone (a stall, a gap, the ramp back after either), with the device
      // healthy and the step fine: what says the build or the machine cannot keep the rate.
      out = scaled_command(out, ceiling);
      bump(s.ramp_cycles);
      bump(s.late_ramp_cycles);
    }
    s.heartbeat_ns.store(write_ns, std::memory_order_release);
    if (try_write(out, &resume)) {
      s.last_written.write_slot() = {out, resume.ceiling()};
      s.last_written.publish();
      last_out = out;
    }
    const std::int64_t c1 = monotonic_ns();
    const double cost_us = 1e-3 * static_cast<double>(c1 - c0);
    cost_us_.record_us(cost_us);
    s.cycles.store(i + 1, std::memory_order_release);

    HapticCycle cycle;
    cycle.index = i;
    cycle.time_s = t_s;
    cycle.input = &input;
    cycle.fresh = fresh;
    cycle.output = &out;
    cycle.cost_us = cost_us;
    cycle.period_us = period_us;
    cycle.healthy = healthy;
    client_.after_cycle(cycle);
  }
  if (faults_after_first_cycle >= 0) {
    const long faults = thread_page_faults();
    s.haptic_page_faults.store(faults >= 0 ? faults - faults_after_first_cycle : -1);
  }
  // Ending (asked to stop, or its cycles done): the last force fades out over the ramp's
  // duration at the loop's rate, as the watchdog's ramp does for a stall, instead of dropping to
  // zero in one cycle (a jolt in the hand when Ctrl-C ends a press). The heartbeat and the last
  // written command go on, so the supervisor sees a loop winding down, not a stall.
  const int fade_cycles =
      static_cast<int>(std::ceil(options_.ramp.ramp_duration_s / options_.period_s - 1e-9));
  for (int k = 1; k < fade_cycles && command_magnitude_n(last_out) > 0.0; ++k) {
    (void)clock.wait_next();
    const DeviceCommand faded =
        scaled_command(last_out, 1.0 - static_cast<double>(k) / static_cast<double>(fade_cycles));
    s.heartbeat_ns.store(monotonic_ns(), std::memory_order_release);
    if (try_write(faded)) {
      s.last_written.write_slot() = {faded, resume.ceiling()};
      s.last_written.publish();
    }
  }
  // Leave the device pushing nothing before anyone can stop watching it (the caller may not
  // reach wait() for a while). The supervisor's ramp base becomes zero too.
  DeviceCommand zero;
  zero.finger_count = device_.profile().finger_count;
  s.last_written.write_slot() = {zero, 0.0};
  s.last_written.publish();
  while (!try_write(zero)) {
    // The supervisor is writing right now: it holds the device for one write only.
  }
  s.end_ns.store(monotonic_ns());
  running_.store(false, std::memory_order_release);
}

// Not on the haptic path: may log (and so allocate) when something happens.
void HapticLoop::supervisor_thread_main() noexcept {
  Shared& s = *shared_;
  // Real-time too where allowed, so a busy machine (the viewer's rasteriser threads) cannot
  // delay its wake-ups, which bound the ramp's timing; one level below the haptic thread, so it
  // never delays a cycle (measured: above it, period jitter p99 rose from ~0.1 to ~45 us).
  if (options_.realtime_priority) {
    (void)try_set_realtime_priority(options_.fifo_priority - 1);
  }
  const auto period_ns =
      static_cast<std::int64_t>(std::llround(options_.supervisor_period_s * 1e9));
  WrittenCommand base;  // the last command the haptic thread wrote
  bool stalled = false;
  std::int64_t stall_start_ns = 0;
  bool healthy_seen = true;
  std::uint64_t gaps_seen = 0;
  std::int64_t next_ns = monotonic_ns();
  while (running_.load(std::memory_order_acquire)) {
    next_ns += period_ns;
    sleep_until_ns(next_ns);
    const std::int64_t now_ns = monotonic_ns();
    next_ns = std::max(next_ns, now_ns - period_ns);  // after a long preemption, no burst
    const std::int64_t heartbeat = s.heartbeat_ns.load(std::memory_order_acquire);
    const double since_s = 1e-9 * static_cast<double>(now_ns - heartbeat);
    // Nothing to watch before the first cycle has written anything (start-up, RT set-up).
    const bool started = s.cycles.load(std::memory_order_acquire) > 0;
    if (started && since_s > options_.ramp.stale_timeout_s &&
        running_.load(std::memory_order_acquire)) {
      if (s.last_written.update()) {
        base = s.last_written.read_slot();
      }
      // Evaluated one supervisor period ahead, so zero is reached by zero_by_s() at the latest.
      const double gain = ramp_gain(since_s + options_.supervisor_period_s, true, options_.ramp);
      // The ceiling first, then the write: a haptic cycle resuming at any point after the device
      // sees the lowered force already finds the lowered ceiling (published after the write, a
      // cycle resuming in between would write full force right after the device saw ~0). If the
      // write does not happen (the haptic thread is writing: it has resumed), the ceiling only
      // makes its force come back over the ramp time.
      // The ceiling is relative to the haptic thread's commanded force: the written one carried
      // base.ceiling of it (a stall during a ramp), so the ceiling is the product, and the force
      // it comes back with starts where this write leaves the device.
      lower_gain(s.supervisor_gain, gain * base.ceiling);
      (void)try_write(scaled_command(base.command, gain));
      if (!stalled) {
        // Logged after the protective write: a blocked stderr must not keep the force on.
        stalled = true;
        stall_start_ns = heartbeat;
        bump(s.stall_events);
        try {
          spdlog::warn(
              "haptic loop: no cycle for {:.1f} ms (the step overran or stalled): ramping the "
              "force to zero within {:.0f} ms",
              since_s * 1e3, options_.ramp.zero_by_s() * 1e3);
        } catch (...) {
        }
      }
    } else if (stalled && since_s <= options_.ramp.stale_timeout_s) {
      stalled = false;
      try {
        spdlog::info(
            "haptic loop: cycles resumed after a {:.1f} ms stall; force comes back over "
            "{:.0f} ms",
            1e-6 * static_cast<double>(heartbeat - stall_start_ns),
            options_.ramp.ramp_duration_s * 1e3);
      } catch (...) {
      }
    }
    const std::uint64_t gaps = s.resume_gaps.load(std::memory_order_acquire);
    if (gaps != gaps_seen) {
      gaps_seen = gaps;
      // Only the gaps that cut the force to zero (a freeze): shorter ones are a busy machine's.
      const double gap_s = 1e-9 * static_cast<double>(s.last_gap_ns.load());
      if (gap_s >= options_.ramp.zero_by_s()) {
        try {
          spdlog::warn(
              "haptic loop: {:.1f} ms since the haptic thread's previous write (the process was "
              "frozen or not scheduled): its force restarted from zero and comes back over "
              "{:.0f} ms",
              gap_s * 1e3, options_.ramp.ramp_duration_s * 1e3);
        } catch (...) {
        }
      }
    }
    const bool healthy = s.device_healthy.load(std::memory_order_relaxed);
    if (healthy != healthy_seen) {
      healthy_seen = healthy;
      try {
        if (!healthy) {
          spdlog::warn(
              "haptic loop: the device reports itself unhealthy (stale or lost): force "
              "ramped to zero");
        } else {
          spdlog::info("haptic loop: the device is healthy again");
        }
      } catch (...) {
      }
    }
  }
}

HapticLoopStatus HapticLoop::status() const noexcept {
  const Shared& s = *shared_;
  HapticLoopStatus st;
  st.running = running();
  st.realtime_priority = s.realtime_priority.load();
  st.memory_locked = s.memory_locked.load();
  st.haptic_page_faults = s.haptic_page_faults.load();
  st.cycles = s.cycles.load(std::memory_order_acquire);
  const std::int64_t start = s.start_ns.load();
  const std::int64_t end = st.running || s.end_ns.load() == 0 ? monotonic_ns() : s.end_ns.load();
  st.elapsed_s = start > 0 ? 1e-9 * static_cast<double>(end - start) : 0.0;
  st.rate_hz = st.elapsed_s > 0.0 ? static_cast<double>(st.cycles) / st.elapsed_s : 0.0;
  st.period_jitter_us = jitter_us_.summary();
  st.cycle_cost_us = cost_us_.summary();
  st.missed_deadlines = s.missed.load();
  st.stall_events = s.stall_events.load();
  st.ramp_cycles = s.ramp_cycles.load();
  st.late_ramp_cycles = s.late_ramp_cycles.load();
  st.device_health_losses = s.health_losses.load();
  st.failed_steps = s.failed_steps.load();
  st.resume_gaps = s.resume_gaps.load();
  st.last_output_force_n = s.last_output_force_n.load();
  if (!st.running) {
    // The watchdog is the haptic thread's; read it only when that thread is done.
    st.clamped_cycles = s.watchdog.clamped_cycles();
    st.nonfinite_commands = s.watchdog.nonfinite_count();
  }
  return st;
}

}  // namespace hapsim
