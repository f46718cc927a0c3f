// The real-time haptic loop: cycles run on their own thread without allocating, a stalled step
// or a device that stops answering makes the supervisor ramp the output to zero and the force come
// back gradually, NaN never reaches the device, forces stay within the profile. Stalls are
// asserted on the order of events in the device's write log (which thread wrote what, and in
// which order), never on how long anything took: without SCHED_FIFO on this shared machine either
// thread may be late by any amount. Injected stalls last until the event they wait for happened.
#include "hapsim/runtime/haptic_loop.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/core/error.h"
#include "hapsim/runtime/deadline_clock.h"
#include "support/allocation_counter.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace hapsim {
namespace {

// A device that logs every write with its time and whether the haptic thread made it (the thread
// of the first read(): only the haptic thread reads; every other write is the supervisor's, or the
// final zero of wait()). The loop serialises writes; the index is atomic anyway. It can be told to
// report itself unhealthy, or to hang inside read() until something happened (e.g. the supervisor
// wrote a zero), and can call a hook on every write that is not the haptic thread's.
class LoggingDevice final : public Device {
 public:
  struct Write {
    std::int64_t t_ns = 0;
    double force_n = 0.0;
    bool finite = true;
    bool haptic = false;
    /// For a haptic write: its cycle (the read() it followed) and when that read began (before
    /// the cycle's heartbeat, which the supervisor's grace is measured from).
    std::uint64_t cycle = 0;
    std::int64_t cycle_read_ns = 0;
  };

  explicit LoggingDevice(DeviceProfile profile) : profile_(std::move(profile)) {
    writes_.resize(200'000);
  }

  DeviceInput read(double time_s) noexcept override {
    const std::uint64_t n = reads_.fetch_add(1);
    if (n == 0) {
      haptic_thread_ = std::this_thread::get_id();
      haptic_known_.store(true, std::memory_order_release);
    }
    last_read_ = n;
    last_read_ns_ = monotonic_ns();
    if (hang_at_read_ >= 0 && hang_started_ns_.load() == 0 &&
        n >= static_cast<std::uint64_t>(hang_at_read_) && last_haptic_n_ >= hang_after_n_) {
      hung_read_ = n;
      hang_started_ns_.store(monotonic_ns(), std::memory_order_release);
      hold_until(hang_until_);
    }
    DeviceInput in;
    in.time_s = time_s;
    in.healthy =
        !(unhealthy_from_read_ >= 0 && n >= static_cast<std::uint64_t>(unhealthy_from_read_));
    return in;
  }
  void write(const DeviceCommand& command) noexcept override {
    const bool haptic = haptic_known_.load(std::memory_order_acquire) &&
                        std::this_thread::get_id() == haptic_thread_;
    const double f = command.force_world_n.norm();
    const std::size_t i = count_.fetch_add(1);
    if (i < writes_.size()) {
      writes_[i] = {monotonic_ns(),          f,
                    std::isfinite(f),        haptic,
                    haptic ? last_read_ : 0, haptic ? last_read_ns_ : 0};
    }
    if (haptic) {
      last_haptic_n_ = f;
    } else {
      if (f == 0.0) {
        last_other_zero_ns_.store(monotonic_ns(), std::memory_order_release);
      }
      if (on_other_write_) {
        on_other_write_(f);
      }
    }
  }
  const DeviceProfile& profile() const noexcept override { return profile_; }
  DeviceStatus status() const noexcept override { return {}; }

  /// The first read() from number `read_index` on that follows a haptic write of `after_n` or
  /// more (a VM hiccup just before may have left the force ramping) hangs until `until` holds (at
  /// most 10 s: a bound on a hang).
  void hang_at(int read_index, double after_n, std::function<bool()> until) {
    hang_at_read_ = read_index;
    hang_after_n_ = after_n;
    hang_until_ = std::move(until);
  }
  void unhealthy_from(int read_index) { unhealthy_from_read_ = read_index; }
  /// Called (on the writing thread, inside write()) for every write not made by the haptic thread.
  void on_other_write(std::function<void(double force_n)> hook) {
    on_other_write_ = std::move(hook);
  }
  /// A thread other than the haptic one (the supervisor: its ramp ended) wrote a zero after
  /// `t_ns` (which must be set: a zero before the event waited for does not count).
  [[nodiscard]] bool other_zero_after(std::int64_t t_ns) const {
    return t_ns != 0 && last_other_zero_ns_.load(std::memory_order_acquire) > t_ns;
  }
  /// The read that hung (once hang_started_ns() is set) and when it began (0 before).
  [[nodiscard]] std::uint64_t hung_read() const { return hung_read_; }
  [[nodiscard]] std::int64_t hang_started_ns() const {
    return hang_started_ns_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::vector<Write> writes() const {
    return {writes_.begin(),
            writes_.begin() + static_cast<std::ptrdiff_t>(std::min(count_.load(), writes_.size()))};
  }

  /// Waits until `until` holds, at most 10 s (only a bound on a hang: tests assert on events).
  static void hold_until(const std::function<bool()>& until) {
    const std::int64_t give_up_ns = monotonic_ns() + 10'000'000'000;
    while (!until() && monotonic_ns() < give_up_ns) {
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  }

 private:
  DeviceProfile profile_;
  std::vector<Write> writes_;
  std::atomic<std::size_t> count_{0};
  std::atomic<std::uint64_t> reads_{0};
  std::thread::id haptic_thread_;
  std::atomic<bool> haptic_known_{false};
  std::uint64_t last_read_ = 0;    // haptic thread only
  std::int64_t last_read_ns_ = 0;  // haptic thread only
  int hang_at_read_ = -1;
  std::uint64_t hung_read_ = 0;
  double hang_after_n_ = 0.0;
  double last_haptic_n_ = 0.0;  // haptic thread only
  std::function<bool()> hang_until_;
  std::atomic<std::int64_t> hang_started_ns_{0};
  int unhealthy_from_read_ = -1;
  std::atomic<std::int64_t> last_other_zero_ns_{0};
  std::function<void(double)> on_other_write_;
};

// A simulation that always asks for the same force, can stall in one step until something
// happened, can return NaN, keeps each cycle's output (what the loop meant to write),
// and counts the haptic thread's allocations from its first to its last step.
class ConstantForceClient final : public HapticClient {
 public:
  explicit ConstantForceClient(const Vec3& force_n) : outputs_(kKeptOutputs, -1.0) {
    command_.force_world_n = force_n;
  }

  const DeviceCommand& step(const DeviceInput& /*input*/, double /*dt_s*/) override {
    const std::uint64_t n = steps_++;
    if (n == 5) {
      allocations_at_start_ = test::thread_allocation_count();
    }
    allocations_at_last_ = test::thread_allocation_count();
    if (stall_at_ >= 0 && stall_started_ns_.load() == 0 &&
        n >= static_cast<std::uint64_t>(stall_at_) && n - 1 < outputs_.size() &&
        outputs_[n - 1] >= command_.force_world_n.norm()) {
      stalled_step_ = n;
      stall_started_ns_.store(monotonic_ns(), std::memory_order_release);
      LoggingDevice::hold_until(stall_until_);
    }
    if (nan_at_ >= 0 && n == static_cast<std::uint64_t>(nan_at_)) {
      nan_command_ = command_;
      nan_command_.force_world_n.x() = std::numeric_limits<double>::quiet_NaN();
      return nan_command_;
    }
    return command_;
  }
  void after_cycle(const HapticCycle& cycle) noexcept override {
    last_cost_us_ = cycle.cost_us;
    if (cycle.index < outputs_.size()) {
      outputs_[cycle.index] = cycle.output->force_world_n.norm();
    }
    cycles_done_.store(cycle.index + 1, std::memory_order_release);
  }
  bool take_soft_start() noexcept override {
    return soft_at_ >= 0 && steps_ == static_cast<std::uint64_t>(soft_at_) + 1;
  }
  void soft_start_at(int step) { soft_at_ = step; }

  /// The first step from `step` on that follows a full-force cycle (a VM hiccup just before may
  /// have left the force ramping) stalls until `until` holds (at most 10 s).
  void stall_at(int step, std::function<bool()> until) {
    stall_at_ = step;
    stall_until_ = std::move(until);
  }
  void nan_at(int step) { nan_at_ = step; }
  /// The step that stalled (once stall_started_ns() is set).
  [[nodiscard]] std::uint64_t stalled_step() const { return stalled_step_; }
  /// When the injected stall began (0 before it did).
  [[nodiscard]] std::int64_t stall_started_ns() const {
    return stall_started_ns_.load(std::memory_order_acquire);
  }
  /// Cycles whose after_cycle() has run.
  [[nodiscard]] std::uint64_t cycles_done() const {
    return cycles_done_.load(std::memory_order_acquire);
  }
  /// Waits (at most 10 s) until cycle `index` has finished; false if it did not.
  [[nodiscard]] bool wait_for_cycle(std::uint64_t index) const {
    LoggingDevice::hold_until([&] { return cycles_done_.load(std::memory_order_acquire) > index; });
    return cycles_done_.load(std::memory_order_acquire) > index;
  }
  /// What cycle `index` meant to write (its output after safety, ramp and resume), N.
  [[nodiscard]] double output_n(std::uint64_t index) const { return outputs_.at(index); }
  [[nodiscard]] long allocations_during_run() const {
    return allocations_at_last_ - allocations_at_start_;
  }

 private:
  static constexpr std::size_t kKeptOutputs = 4096;
  DeviceCommand command_;
  DeviceCommand nan_command_;
  std::uint64_t steps_ = 0;
  int stall_at_ = -1;
  std::function<bool()> stall_until_;
  int nan_at_ = -1;
  int soft_at_ = -1;
  std::uint64_t stalled_step_ = 0;
  std::atomic<std::int64_t> stall_started_ns_{0};
  std::vector<double> outputs_;
  std::atomic<std::uint64_t> cycles_done_{0};
  long allocations_at_start_ = 0;
  long allocations_at_last_ = 0;
  double last_cost_us_ = 0.0;
};

// For tests that are not about stalls: a shared VM stalls the whole CPU for a few ms now and
// then, which would (rightly) make the supervisor ramp; a long grace keeps it out of these tests.
HapticLoopOptions quick_options(std::uint64_t cycles) {
  HapticLoopOptions o;
  o.max_cycles = cycles;
  o.ramp.stale_timeout_s = 0.5;
  return o;
}

// For the stall tests: the default 2 ms grace and 8 ms ramp.
HapticLoopOptions stall_options(std::uint64_t cycles) {
  HapticLoopOptions o;
  o.max_cycles = cycles;
  return o;
}

// Runs `loop` (endless: max_cycles 0) until `done` holds, at most 10 s (only a bound on a hang),
// then stops it: a test that injects a stall runs until the stall happened and the force came back,
// however busy the machine is.
void run_until(HapticLoop& loop, const std::function<bool()>& done) {
  loop.start();
  LoggingDevice::hold_until(done);
  loop.stop();
}

// A stall in the write log: the haptic thread's last write before it began and its first after.
struct StallWrites {
  std::size_t last_good = 0;
  std::size_t resumed = 0;
};

std::optional<StallWrites> find_stall(const std::vector<LoggingDevice::Write>& w,
                                      std::int64_t began_ns) {
  std::optional<std::size_t> last_good;
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (!w[i].haptic) {
      continue;
    }
    if (w[i].t_ns < began_ns) {
      last_good = i;
    } else if (last_good) {
      return StallWrites{*last_good, i};
    }
  }
  return std::nullopt;
}

// What a stall must do to the device, checked on the order of events, never on how long anything
// took (the supervisor's gain comes from its own clock read, ahead of its write, and a busy machine
// delays either thread arbitrarily):
// - ramp down: the supervisor's writes between the haptic thread's last write before the stall and
//   its first after exist, never rise, end at exactly 0, and none is below the last good force
//   before the grace has passed (stale_timeout_s after the last good cycle read the device, which
//   is no later than its heartbeat);
// - ramp up: the haptic thread's first write after the stall is below half of f0, no later write
//   rises by more than one ramp step (f0 · period / ramp_duration) per cycle, the force rises at
//   least ramp_cycles − 1 times on its way back (one fewer if the resumed cycle's own write lost
//   to a supervisor write) and it does reach f0 again.
// Returns what is wrong (nothing: an empty list).
std::vector<std::string> stall_ramp_problems(const std::vector<LoggingDevice::Write>& w,
                                             const StallWrites& stall, double f0_n,
                                             const HapticLoopOptions& options) {
  std::vector<std::string> problems;
  const auto say = [&](const std::string& what, std::size_t i) {
    problems.push_back(what + " (write " + std::to_string(i) + ": " + std::to_string(w[i].force_n) +
                       " N)");
  };
  const LoggingDevice::Write& good = w[stall.last_good];
  const std::int64_t grace_end_ns =
      good.cycle_read_ns + std::llround(options.ramp.stale_timeout_s * 1e9);
  std::optional<std::size_t> previous;
  for (std::size_t i = stall.last_good + 1; i < stall.resumed; ++i) {
    if (w[i].force_n < good.force_n - 1e-12 && w[i].t_ns < grace_end_ns) {
      say("the supervisor lowered the force within the grace time", i);
    }
    if (previous && w[i].force_n > w[*previous].force_n + 1e-12) {
      say("the supervisor's ramp rose", i);
    }
    previous = i;
  }
  if (!previous) {
    problems.emplace_back("the supervisor wrote nothing during the stall");
  } else if (w[*previous].force_n != 0.0) {
    say("the supervisor's ramp did not end at exactly zero", *previous);
  }

  const int ramp_cycles =
      static_cast<int>(std::lround(options.ramp.ramp_duration_s / options.period_s));
  const double ramp_step_n = f0_n / ramp_cycles;
  if (w[stall.resumed].force_n >= 0.5 * f0_n) {
    say("the force jumped back after the stall", stall.resumed);
  }
  std::size_t last = stall.resumed;
  int rises = 0;
  bool back = false;
  for (std::size_t i = stall.resumed + 1; i < w.size(); ++i) {
    if (!w[i].haptic) {
      continue;
    }
    const auto cycles = static_cast<double>(w[i].cycle - w[last].cycle);
    if (w[i].force_n > w[last].force_n + ramp_step_n * cycles + 1e-9) {
      say("the force came back faster than the ramp", i);
    }
    if (!back && w[i].force_n > w[last].force_n + 1e-12) {
      ++rises;
    }
    back = back || w[i].force_n >= f0_n - 1e-9;
    last = i;
  }
  if (!back) {
    problems.emplace_back("the force never came back to " + std::to_string(f0_n) + " N");
  }
  if (rises < ramp_cycles - 1) {
    problems.push_back("the force came back in " + std::to_string(rises) + " rise(s), not " +
                       std::to_string(ramp_cycles - 1) + " or more");
  }
  return problems;
}

// A log as the stall checks expect it: f0 from the haptic thread (cycles 0-4, each read at c ms),
// the stall, the supervisor's ramp after the 2 ms grace, then the haptic thread back from 0 over
// the ramp's 8 cycles.
std::vector<LoggingDevice::Write> good_stall_log(double f0) {
  std::vector<LoggingDevice::Write> w;
  const auto haptic = [&](std::uint64_t cycle, double t_ms, double f) {
    const auto t_ns = static_cast<std::int64_t>(t_ms * 1e6);
    w.push_back({t_ns + 10'000, f, true, true, cycle, t_ns});
  };
  for (std::uint64_t c = 0; c < 5; ++c) {
    haptic(c, static_cast<double>(c), f0);
  }
  for (const double g : {0.8, 0.5, 0.2, 0.0, 0.0}) {
    w.push_back(
        {static_cast<std::int64_t>((6.5 + 10.0 * (0.8 - g)) * 1e6), f0 * g, true, false, 0, 0});
  }
  for (std::uint64_t c = 5; c < 20; ++c) {
    haptic(c, static_cast<double>(c) + 40.0, f0 * std::min(1.0, static_cast<double>(c - 5) / 8.0));
  }
  return w;
}

TEST(HapticLoop, RunsTheCyclesAndMeasuresThem) {
  LoggingDevice device(device_profile("omega3"));
  ConstantForceClient client(Vec3(0, 0, 2.0));
  HapticLoop loop(device, client, quick_options(300));
  loop.start();
  EXPECT_THROW(loop.start(), Error);
  loop.wait();
  const HapticLoopStatus st = loop.status();
  EXPECT_FALSE(st.running);
  EXPECT_EQ(st.cycles, 300u);
  EXPECT_EQ(st.cycle_cost_us.count, 300u);
  EXPECT_EQ(st.period_jitter_us.count, 299u);  // a period needs two cycles
  EXPECT_LE(st.period_jitter_us.p50, st.period_jitter_us.p99);
  EXPECT_LE(st.period_jitter_us.p99, st.period_jitter_us.max);
  EXPECT_GT(st.rate_hz, 0.0);
  EXPECT_EQ(st.failed_steps, 0u);
  const auto writes = device.writes();
  ASSERT_GE(writes.size(), 301u);  // 300 cycles and the final zero (the supervisor may add some)
  EXPECT_EQ(writes.back().force_n, 0.0);  // stopping leaves the device pushing nothing
  const auto full = std::count_if(writes.begin(), writes.end(),
                                  [](const auto& w) { return std::abs(w.force_n - 2.0) < 1e-12; });
  EXPECT_GE(full, 290);
  for (std::size_t i = 1; i < writes.size(); ++i) {
    EXPECT_GE(writes[i].t_ns, writes[i - 1].t_ns);
  }
}

TEST(HapticLoop, HapticThreadAllocatesNothing) {
  LoggingDevice device(device_profile("omega3"));
  ConstantForceClient client(Vec3(0, 0, 1.0));
  HapticLoop loop(device, client, quick_options(400));
  loop.start();
  // Other threads may allocate meanwhile (this one reads the live status, as the viewer does).
  for (int i = 0; i < 20 && loop.running(); ++i) {
    (void)loop.status();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  loop.wait();
  EXPECT_EQ(client.allocations_during_run(), 0);
  EXPECT_EQ(loop.status().cycles, 400u);
}

// The stall checks can fail: they pass the log of a good stall and find something wrong with each
// broken one (no supervisor ramp, a ramp within the grace, one that rises or stops short of zero;
// a ramp back that is skipped, too fast, or stops short).
TEST(HapticLoop, StallChecksRejectBrokenRamps) {
  const double f0 = 4.0;
  const HapticLoopOptions options = stall_options(0);
  const StallWrites stall{4, 10};
  const auto problems = [&](const std::vector<LoggingDevice::Write>& w) {
    const auto found = find_stall(w, 4'500'000);
    EXPECT_TRUE(found && found->last_good == stall.last_good && found->resumed == stall.resumed);
    return stall_ramp_problems(w, stall, f0, options);
  };
  const auto good = good_stall_log(f0);
  const auto good_problems = problems(good);
  EXPECT_TRUE(good_problems.empty()) << good_problems.front();

  auto w = good;
  w.erase(w.begin() + 5, w.begin() + 10);  // no supervisor at all
  EXPECT_FALSE(stall_ramp_problems(w, StallWrites{4, 5}, f0, options).empty());
  w = good;
  w[5].t_ns = 5'000'000;  // lowered 1 ms after the last good read: within the 2 ms grace
  EXPECT_FALSE(problems(w).empty());
  w = good;
  w[7].force_n = w[6].force_n + 0.1;  // the ramp rises
  EXPECT_FALSE(problems(w).empty());
  w = good;
  w[8].force_n = w[9].force_n = 0.01;  // not exactly zero
  EXPECT_FALSE(problems(w).empty());
  w = good;
  for (std::size_t i = 10; i < w.size(); ++i) {
    w[i].force_n = f0;  // the ramp back skipped: full force at once
  }
  EXPECT_FALSE(problems(w).empty());
  w = good;
  for (std::size_t i = 11; i < w.size(); ++i) {
    w[i].force_n = f0;  // from zero to full force in one cycle
  }
  EXPECT_FALSE(problems(w).empty());
  w = good;
  for (std::size_t i = 10; i < w.size(); ++i) {
    w[i].force_n = f0 * std::min(1.0, static_cast<double>(i - 10) / 4.0);  // twice as fast
  }
  EXPECT_FALSE(problems(w).empty());
  w = good;
  for (std::size_t i = 10; i < w.size(); ++i) {
    w[i].force_n *= 0.5;  // never back to full force
  }
  EXPECT_FALSE(problems(w).empty());
}

// A step stalls (until the supervisor has ramped the force to zero: the stall's length is an
// event, not a time): the supervisor ramps the last good force to zero after the grace, and the
// force comes back gradually when cycles resume. Checked on the write log's events only.
TEST(HapticLoop, StalledStepRampsForceToZeroThenComesBackGradually) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 4.0;
  ConstantForceClient client(Vec3(f0, 0, 0));
  client.stall_at(200, [&] { return device.other_zero_after(client.stall_started_ns()); });
  const HapticLoopOptions options = stall_options(0);
  HapticLoop loop(device, client, options);
  run_until(loop, [&] {
    return client.stall_started_ns() != 0 && client.cycles_done() > client.stalled_step() + 50;
  });
  const auto w = device.writes();
  const auto stall = find_stall(w, client.stall_started_ns());
  ASSERT_TRUE(stall) << "no haptic write on both sides of the stall";
  for (const std::string& problem : stall_ramp_problems(w, *stall, f0, options)) {
    ADD_FAILURE() << problem;
  }
  const HapticLoopStatus st = loop.status();
  EXPECT_GE(st.stall_events, 1u);      // the injected one (a VM hiccup may add its own)
  EXPECT_GE(st.missed_deadlines, 1u);  // the stalled period
  EXPECT_GT(st.ramp_cycles, 0u);
}

TEST(HapticLoop, DeviceThatHangsInReadIsRampedBySupervisor) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 3.0;
  ConstantForceClient client(Vec3(0, f0, 0));
  device.hang_at(150, f0, [&] { return device.other_zero_after(device.hang_started_ns()); });
  const HapticLoopOptions options = stall_options(0);
  HapticLoop loop(device, client, options);
  run_until(loop, [&] {
    return device.hang_started_ns() != 0 && loop.status().cycles > device.hung_read() + 50;
  });
  const auto w = device.writes();
  const auto stall = find_stall(w, device.hang_started_ns());
  ASSERT_TRUE(stall) << "no haptic write on both sides of the hang";
  for (const std::string& problem : stall_ramp_problems(w, *stall, f0, options)) {
    ADD_FAILURE() << problem;
  }
  EXPECT_GE(loop.status().stall_events, 1u);
}

// The supervisor's ramp is a ceiling for the haptic thread as well: once the device has seen the
// supervisor's lowered force, the cycle that resumes after the stall must not write more than that
// (full force right after ~0 is the kick the ramp exists to prevent). The stalled cycle is let go
// while the supervisor's first write is still inside the device, so it resumes in the window
// between that write and whatever the supervisor does after it.
TEST(HapticLoop, SupervisorLowersTheCeilingBeforeTheDeviceSeesItsRamp) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 4.0;
  ConstantForceClient client(Vec3(f0, 0, 0));
  std::atomic<bool> release{false};
  client.stall_at(200, [&] { return release.load(); });
  double supervisor_n = -1.0;  // the supervisor's first write during the stall
  bool resumed = false;
  std::atomic<bool> done{false};
  device.on_other_write([&](double force_n) {
    if (client.stall_started_ns() == 0 || release.load()) {
      return;  // a hiccup of this VM before the injected stall, or the final zero
    }
    supervisor_n = force_n;
    release.store(true);
    resumed = client.wait_for_cycle(client.stalled_step());
    done.store(true);
  });
  HapticLoop loop(device, client, stall_options(0));
  run_until(loop, [&] { return done.load(); });
  ASSERT_GE(supervisor_n, 0.0) << "the supervisor never wrote during the stall";
  const std::uint64_t stalled = client.stalled_step();
  ASSERT_TRUE(resumed) << "the stalled cycle never finished";
  // The supervisor scaled the haptic thread's last write before the stall by its gain.
  const auto w = device.writes();
  double base_n = -1.0;
  for (const auto& write : w) {
    if (write.haptic && write.t_ns < client.stall_started_ns()) {
      base_n = write.force_n;
    }
  }
  ASSERT_GT(base_n, 0.0);
  EXPECT_LT(supervisor_n, base_n) << "the supervisor's write was not a ramp";
  const double gain = supervisor_n / base_n;
  EXPECT_LE(client.output_n(stalled), f0 * gain + 1e-9)
      << "the cycle after the stall meant to write " << client.output_n(stalled)
      << " N right after the device saw " << supervisor_n << " N";
}

// A log sink that holds the thread logging a warning (stderr into a full pipe) while `armed` and
// until it is opened; at most 10 s (then it notes that it gave up).
class BlockingSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit BlockingSink(std::function<bool()> armed) : armed_(std::move(armed)) {}
  void open() { open_.store(true); }
  [[nodiscard]] bool gave_up() const { return gave_up_.load(); }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    if (msg.level >= spdlog::level::warn && armed_()) {
      LoggingDevice::hold_until([this] { return open_.load(); });
      gave_up_.store(!open_.load());
    }
  }
  void flush_() override {}

 private:
  std::function<bool()> armed_;
  std::atomic<bool> open_{false};
  std::atomic<bool> gave_up_{false};
};

// The supervisor protects the device first and tells people after: a warning that cannot get out
// (stderr blocked) must not keep the force on the device.
TEST(HapticLoop, SupervisorWritesBeforeItLogs) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 4.0;
  ConstantForceClient client(Vec3(0, 0, f0));
  std::atomic<bool> release{false};
  client.stall_at(200, [&] { return release.load(); });
  // Warnings block from the injected stall on (a hiccup of this VM before it may log freely).
  auto sink = std::make_shared<BlockingSink>([&] { return client.stall_started_ns() != 0; });
  double supervisor_n = -1.0;
  device.on_other_write([&](double force_n) {
    if (client.stall_started_ns() == 0 || release.load()) {
      return;
    }
    supervisor_n = force_n;
    sink->open();  // only a write during the stall lets the log go
    release.store(true);
  });
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("blocked stderr", sink));
  {
    HapticLoop loop(device, client, stall_options(0));
    run_until(loop, [&] { return release.load(); });
  }
  spdlog::set_default_logger(previous);
  EXPECT_FALSE(sink->gave_up()) << "the supervisor waited for its log before writing";
  ASSERT_GE(supervisor_n, 0.0) << "the supervisor never wrote during the stall";
  EXPECT_LT(supervisor_n, f0);
}

TEST(HapticLoop, DeviceReportingItselfUnhealthyRampsToZeroAndStays) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 5.0;
  ConstantForceClient client(Vec3(0, 0, -f0));
  device.unhealthy_from(100);
  ForceRampParams ramp;
  HapticLoop loop(device, client, quick_options(200));
  loop.start();
  loop.wait();
  const auto w = device.writes();
  // Cycle 99 was the last healthy one: from 100 on the watchdog ramps with no grace period.
  ASSERT_GE(w.size(), 200u);
  std::size_t last_good = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (w[i].force_n >= f0 - 1e-9) {
      last_good = i;
    }
  }
  ASSERT_GE(last_good, 98u);
  std::size_t first_zero = last_good + 1;
  while (first_zero < w.size() && w[first_zero].force_n > 0.0) {
    ++first_zero;
  }
  ASSERT_LT(first_zero, w.size());
  for (std::size_t i = last_good + 1; i < w.size(); ++i) {
    const double since_s = 1e-9 * static_cast<double>(w[i].t_ns - w[last_good].t_ns);
    // Unhealthy: no grace, linear over ramp_duration_s (one cycle of slack for the watchdog
    // measuring from the cycle's start rather than the write).
    const double bound = f0 * std::max(0.0, 1.0 - (since_s - 0.001) / ramp.ramp_duration_s);
    EXPECT_LE(w[i].force_n, bound + 1e-9) << "write " << i;
    EXPECT_LE(w[i].force_n, w[i - 1].force_n + 1e-12);
  }
  EXPECT_EQ(w.back().force_n, 0.0);
  const HapticLoopStatus st = loop.status();
  EXPECT_EQ(st.device_health_losses, 1u);
  // The watchdog capped every cycle from 100 on; none of that is lateness. (A cycle late by
  // chance on a busy machine would be, so that is checked only when none came late.)
  EXPECT_GE(st.ramp_cycles, st.cycles - 100);
  if (st.stall_events == 0 && st.resume_gaps == 0) {
    EXPECT_EQ(st.ramp_cycles, st.cycles - 100);
    EXPECT_EQ(st.late_ramp_cycles, 0u);
  }
}

TEST(HapticLoop, NanCommandNeverReachesTheDeviceAndForceIsClamped) {
  const DeviceProfile& omega = device_profile("omega3");
  LoggingDevice device(omega);
  ConstantForceClient client(Vec3(0, 0, 10.0 * omega.max_force_n));
  client.nan_at(50);
  HapticLoop loop(device, client, quick_options(100));
  loop.start();
  loop.wait();
  const auto w = device.writes();
  ASSERT_GE(w.size(), 100u);
  for (const auto& write : w) {
    EXPECT_TRUE(write.finite);
    EXPECT_LE(write.force_n, omega.max_force_n + 1e-9);
  }
  EXPECT_NEAR(w[10].force_n, omega.max_force_n, 1e-9);
  const HapticLoopStatus st = loop.status();
  EXPECT_GE(st.nonfinite_commands, 1u);
  EXPECT_GE(st.clamped_cycles, 99u);
}

TEST(HapticLoop, StopRequestEndsAnEndlessLoop) {
  LoggingDevice device(device_profile("touch"));
  ConstantForceClient client(Vec3(1, 0, 0));
  HapticLoop loop(device, client);  // max_cycles = 0: until stopped
  loop.start();
  while (loop.status().cycles < 20) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  loop.stop();
  EXPECT_FALSE(loop.running());
  EXPECT_GE(loop.status().cycles, 20u);
  EXPECT_EQ(device.writes().back().force_n, 0.0);
  loop.stop();  // idempotent
}

// Asked to stop mid-press (Ctrl-C, SIGTERM), the loop fades the force out over the ramp's
// duration at its own rate, never up, and ends at zero: dropped in one cycle from 6 N it was a
// jolt in the hand.
TEST(HapticLoop, StoppingMidPressFadesTheForceOutOverTheRampTime) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 6.0;
  ConstantForceClient client(Vec3(0, 0, f0));
  const HapticLoopOptions options;  // until stopped
  HapticLoop loop(device, client, options);
  loop.start();
  while (loop.status().cycles < 50) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  loop.stop();
  std::vector<double> haptic;
  for (const auto& write : device.writes()) {
    if (write.haptic) {
      haptic.push_back(write.force_n);
    }
  }
  // The last cycle's force (f0, or less when a loaded machine's gap cut it), then the fade: k/n
  // of the way down at the k-th of the ramp's n cycles, the last one the zero.
  const auto n =
      static_cast<std::size_t>(std::lround(options.ramp.ramp_duration_s / options.period_s));
  ASSERT_GT(haptic.size(), n + 40);
  const std::size_t fade_begin = haptic.size() - n;
  const double from_n = haptic[fade_begin - 1];
  ASSERT_GT(from_n, 0.0);
  EXPECT_LE(from_n, f0);
  for (std::size_t k = 1; k <= n; ++k) {
    EXPECT_NEAR(haptic[fade_begin + k - 1], from_n * static_cast<double>(n - k) / n, 1e-9) << k;
  }
  EXPECT_EQ(device.writes().back().force_n, 0.0);
}

TEST(HapticLoop, EndingByItselfLeavesTheDeviceAtZeroBeforeAnyoneWaits) {
  LoggingDevice device(device_profile("omega3"));
  ConstantForceClient client(Vec3(0, 0, 4.0));
  HapticLoop loop(device, client, quick_options(100));
  loop.start();
  while (loop.running()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // Not waited for yet: the haptic thread's own last write was zero.
  const auto w = device.writes();
  ASSERT_GE(w.size(), 101u);
  EXPECT_EQ(w.back().force_n, 0.0);
  loop.wait();
}

TEST(HapticLoop, SoftStartBringsTheForceBackOverTheRampTime) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 6.0;
  ConstantForceClient client(Vec3(f0, 0, 0));
  client.soft_start_at(100);  // e.g. a simulation resumed after a pause
  const HapticLoopOptions options = quick_options(200);
  HapticLoop loop(device, client, options);
  loop.start();
  loop.wait();
  const auto w = device.writes();
  ASSERT_GE(w.size(), 200u);
  EXPECT_NEAR(w[99].force_n, f0, 1e-9);
  // From zero, up in equal steps, full at the end of the ramp time (8 cycles of 1 ms).
  const int ramp_cycles =
      static_cast<int>(std::lround(options.ramp.ramp_duration_s / options.period_s));
  for (int i = 0; i < ramp_cycles; ++i) {
    EXPECT_NEAR(w[static_cast<std::size_t>(100 + i)].force_n, f0 * (i + 1) / ramp_cycles, 1e-9)
        << i;
  }
  EXPECT_LT(w[100].force_n, 0.2 * f0);
}

TEST(HapticLoop, BadOptionsAreErrors) {
  LoggingDevice device(device_profile("touch"));
  ConstantForceClient client(Vec3::Zero());
  HapticLoopOptions o;
  o.period_s = 0.0;
  EXPECT_THROW(HapticLoop bad(device, client, o), Error);
  o = HapticLoopOptions{};
  o.ramp.ramp_duration_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(HapticLoop bad(device, client, o), Error);
}

}  // namespace
}  // namespace hapsim
