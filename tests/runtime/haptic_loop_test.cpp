// The real-time haptic loop: cycles run on their own thread without allocating, a stalled step
// or a device that stops answering makes the output ramp to zero along the bounded profile
// (force_safety.h) and come back gradually, NaN never reaches the device, forces stay within the
// profile. Timing is asserted only through the loop's own timestamps (the ramp as a function of
// the time since the last good cycle), never as wall-clock bounds on this shared machine.
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
    /// For a haptic write: when its cycle read the device (before that cycle's heartbeat).
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
    last_read_ns_ = monotonic_ns();
    if (hang_at_read_ >= 0 && n == static_cast<std::uint64_t>(hang_at_read_)) {
      hang_started_ns_.store(monotonic_ns());
      if (hang_until_) {
        hold_until(hang_until_);
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(hang_ms_));
      }
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
      writes_[i] = {monotonic_ns(), f, std::isfinite(f), haptic, haptic ? last_read_ns_ : 0};
    }
    if (!haptic) {
      if (f == 0.0) {
        other_zero_seen_.store(true, std::memory_order_release);
      }
      if (on_other_write_) {
        on_other_write_(f);
      }
    }
  }
  const DeviceProfile& profile() const noexcept override { return profile_; }
  DeviceStatus status() const noexcept override { return {}; }

  void hang_at(int read_index, int ms) {
    hang_at_read_ = read_index;
    hang_ms_ = ms;
  }
  /// read() number `read_index` hangs until `until` holds (at most 10 s: a bound on a hang).
  void hang_at(int read_index, std::function<bool()> until) {
    hang_at_read_ = read_index;
    hang_until_ = std::move(until);
  }
  void unhealthy_from(int read_index) { unhealthy_from_read_ = read_index; }
  /// Called (on the writing thread, inside write()) for every write not made by the haptic thread.
  void on_other_write(std::function<void(double force_n)> hook) {
    on_other_write_ = std::move(hook);
  }
  /// A zero was written by a thread other than the haptic one (the supervisor's ramp ended).
  [[nodiscard]] bool other_zero_seen() const {
    return other_zero_seen_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::int64_t hang_started_ns() const { return hang_started_ns_.load(); }
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
  std::int64_t last_read_ns_ = 0;  // haptic thread only
  int hang_at_read_ = -1;
  int hang_ms_ = 0;
  std::function<bool()> hang_until_;
  std::atomic<std::int64_t> hang_started_ns_{0};
  int unhealthy_from_read_ = -1;
  std::atomic<bool> other_zero_seen_{false};
  std::function<void(double)> on_other_write_;
};

// A simulation that always asks for the same force, can stall in one step (for a time, or until
// something happened), can return NaN, keeps each cycle's output (what the loop meant to write),
// and counts the haptic thread's allocations from its first to its last step.
class ConstantForceClient final : public HapticClient {
 public:
  explicit ConstantForceClient(Vec3 force_n) : outputs_(kKeptOutputs, -1.0) {
    command_.force_world_n = force_n;
  }

  const DeviceCommand& step(const DeviceInput& /*input*/, double /*dt_s*/) override {
    const std::uint64_t n = steps_++;
    if (n == 5) {
      allocations_at_start_ = test::thread_allocation_count();
    }
    allocations_at_last_ = test::thread_allocation_count();
    if (stall_at_ >= 0 && n == static_cast<std::uint64_t>(stall_at_)) {
      stall_started_ns_.store(monotonic_ns(), std::memory_order_release);
      if (stall_until_) {
        LoggingDevice::hold_until(stall_until_);
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(stall_ms_));
      }
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

  void stall_at(int step, int ms) {
    stall_at_ = step;
    stall_ms_ = ms;
  }
  /// Step `step` stalls until `until` holds (at most 10 s).
  void stall_at(int step, std::function<bool()> until) {
    stall_at_ = step;
    stall_until_ = std::move(until);
  }
  void nan_at(int step) { nan_at_ = step; }
  /// When the injected stall began (0 before it did).
  [[nodiscard]] std::int64_t stall_started_ns() const {
    return stall_started_ns_.load(std::memory_order_acquire);
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
  int stall_ms_ = 0;
  std::function<bool()> stall_until_;
  int nan_at_ = -1;
  int soft_at_ = -1;
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

// The first write below `f0` at or after `from_ns` (the event under test; a VM hiccup before it
// may have ramped too), and the last full-force write before it.
std::pair<std::size_t, std::size_t> ramp_start(const std::vector<LoggingDevice::Write>& w,
                                               double f0, std::int64_t from_ns) {
  for (std::size_t i = 1; i < w.size(); ++i) {
    if (w[i].t_ns >= from_ns && w[i].force_n < f0 - 1e-9) {
      std::size_t good = i;
      while (good > 0 && w[good].force_n < f0 - 1e-9) {
        --good;
      }
      return {good, i};
    }
  }
  return {0, 0};
}

// Every write after the last full-force write before `from_ns` must lie under the ramp profile
// measured from that write's time: force <= F0 · ramp_gain(t - t_good).
void expect_under_ramp_profile(const std::vector<LoggingDevice::Write>& writes, double f0_n,
                               std::size_t first_low, const ForceRampParams& ramp,
                               std::int64_t t_good_ns, std::size_t end) {
  for (std::size_t i = first_low; i < end; ++i) {
    const double since_s = 1e-9 * static_cast<double>(writes[i].t_ns - t_good_ns);
    const double bound = f0_n * ramp_gain(since_s, true, ramp) + 1e-9;
    EXPECT_LE(writes[i].force_n, bound) << "write " << i << " at " << since_s * 1e3 << " ms";
  }
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

TEST(HapticLoop, StalledStepRampsForceToZeroThenComesBackGradually) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 4.0;
  ConstantForceClient client(Vec3(f0, 0, 0));
  client.stall_at(200, 60);  // one step takes 60 ms
  const HapticLoopOptions options = stall_options(400);
  HapticLoop loop(device, client, options);
  loop.start();
  loop.wait();
  const auto w = device.writes();
  // The last full-force write before the stall, then the supervisor's writes.
  const auto [good, first_low] = ramp_start(w, f0, client.stall_started_ns());
  ASSERT_GT(first_low, 0u) << "no ramp found";
  const std::int64_t t_good = w[good].t_ns;
  // The stall lasts 60 ms: the supervisor reaches zero and writes zeros until cycles resume.
  std::size_t first_zero = 0;
  for (std::size_t i = first_low; i < w.size(); ++i) {
    if (w[i].force_n == 0.0) {
      first_zero = i;
      break;
    }
  }
  ASSERT_GT(first_zero, 0u) << "the force never reached zero during a 60 ms stall";
  // The ramp is monotone and never above the bounded profile (zero by zero_by_s() = 10 ms).
  std::size_t resume = first_zero;
  while (resume < w.size() && w[resume].force_n == 0.0) {
    ++resume;
  }
  for (std::size_t i = first_low; i <= first_zero; ++i) {
    EXPECT_LE(w[i].force_n, w[i - 1].force_n + 1e-12);
  }
  expect_under_ramp_profile(w, f0, first_low, options.ramp, t_good, first_zero + 1);
  const double zero_after_ms = 1e-6 * static_cast<double>(w[first_zero].t_ns - t_good);
  EXPECT_GT(zero_after_ms, 1e3 * options.ramp.stale_timeout_s);  // not before the grace
  // Back again: no jump to full force, a ramp up over ramp_duration_s.
  ASSERT_LT(resume + 3, w.size());
  EXPECT_LT(w[resume].force_n, 0.5 * f0) << "force jumped back after the stall";
  EXPECT_LT(w[resume].force_n, w[resume + 3].force_n);
  double after = 0.0;  // and it does come back fully
  for (std::size_t i = resume; i < w.size(); ++i) {
    after = std::max(after, w[i].force_n);
  }
  EXPECT_NEAR(after, f0, 1e-9);
  const HapticLoopStatus st = loop.status();
  EXPECT_GE(st.stall_events, 1u);      // the injected one (a VM hiccup may add its own)
  EXPECT_GE(st.missed_deadlines, 1u);  // the 60 ms period
  EXPECT_GT(st.ramp_cycles, 0u);
  EXPECT_GE(st.period_jitter_us.max, 50'000.0);
}

TEST(HapticLoop, DeviceThatHangsInReadIsRampedBySupervisor) {
  LoggingDevice device(device_profile("omega3"));
  const double f0 = 3.0;
  ConstantForceClient client(Vec3(0, f0, 0));
  device.hang_at(150, 50);
  const HapticLoopOptions options = stall_options(300);
  HapticLoop loop(device, client, options);
  loop.start();
  loop.wait();
  const auto w = device.writes();
  const auto [good, first_low] = ramp_start(w, f0, device.hang_started_ns());
  ASSERT_GT(first_low, 0u) << "no ramp found";
  std::size_t first_zero = first_low;
  while (first_zero < w.size() && w[first_zero].force_n > 0.0) {
    ++first_zero;
  }
  ASSERT_LT(first_zero, w.size() - 1) << "the force never reached zero during a 50 ms hang";
  expect_under_ramp_profile(w, f0, first_low, options.ramp, w[good].t_ns, first_zero + 1);
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
  constexpr std::uint64_t kStalled = 200;
  std::atomic<bool> release{false};
  client.stall_at(static_cast<int>(kStalled), [&] { return release.load(); });
  double supervisor_n = -1.0;  // the supervisor's first write during the stall
  bool resumed = false;
  device.on_other_write([&](double force_n) {
    if (client.stall_started_ns() == 0 || release.load()) {
      return;  // a hiccup of this VM before the injected stall, or the final zero
    }
    supervisor_n = force_n;
    release.store(true);
    resumed = client.wait_for_cycle(kStalled);
  });
  HapticLoop loop(device, client, stall_options(kStalled + 100));
  loop.start();
  loop.wait();
  ASSERT_GE(supervisor_n, 0.0) << "the supervisor never wrote during the stall";
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
  EXPECT_LE(client.output_n(kStalled), f0 * gain + 1e-9)
      << "the cycle after the stall meant to write " << client.output_n(kStalled)
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
  constexpr int kStalled = 200;
  std::atomic<bool> release{false};
  client.stall_at(kStalled, [&] { return release.load(); });
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
    HapticLoop loop(device, client, stall_options(kStalled + 100));
    loop.start();
    loop.wait();
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
  EXPECT_EQ(loop.status().device_health_losses, 1u);
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
