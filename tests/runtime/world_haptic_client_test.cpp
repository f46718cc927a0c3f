// The World on the real-time loop: the snapshot a viewer reads is the world's state exactly
// (deformed vertices copied by delta match the world's surface bit for bit as floats, tools match
// the device input), a reader thread never sees a torn snapshot, the haptic thread allocates
// nothing with a real World, and a real-time session reports the same contacts as an inline one.
#include "hapsim/runtime/world_haptic_client.h"

#include "hapsim/core/device_profile.h"
#include "hapsim/deform/vertex_deflection.h"
#include "hapsim/device/recording.h"
#include "hapsim/device/simulated_device.h"
#include "hapsim/geometry/procedural.h"
#include "hapsim/runtime/deadline_clock.h"
#include "hapsim/runtime/session.h"
#include "hapsim/scene/run_setup.h"
#include "hapsim/scene/scene_device.h"
#include "hapsim/scene/scene_file.h"
#include "runtime/two_body_world.h"
#include "support/allocation_counting_client.h"
#include "support/replay_check.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <thread>

#include <unistd.h>

namespace hapsim {
namespace {

// Presses the soft ball 6 mm deep in a 0.4 s sine, then lifts away (the dent recovers).
DeviceInput press_ball(double t) {
  DeviceInput in;
  in.time_s = t;
  const double depth = t < 0.4 ? 0.006 * std::sin(3.141592653589793 * t / 0.4) : -0.01;
  in.p_world = Vec3(0.2, 0.0, 0.004 - depth);
  return in;
}

// Wraps a device so that the loop stalls once while the force is on: the first read() from number
// `from_read` on that follows a haptic write of at least `min_force_n` hangs until the supervisor
// (a write from a thread other than the one that reads) has ramped the force to zero (10 s at
// most: only a bound on a hang). The stall is an event, not a time: the supervisor's ramp and the
// loop's gradual return are in the run however the machine is scheduled.
class StallingDevice final : public Device {
 public:
  StallingDevice(Device& inner, std::uint64_t from_read, double min_force_n)
      : inner_(inner), from_read_(from_read), min_force_n_(min_force_n) {}

  DeviceInput read(double time_s) noexcept override {
    const std::uint64_t n = reads_++;
    if (n == 0) {
      reader_ = std::this_thread::get_id();
      reader_known_.store(true, std::memory_order_release);
    }
    if (!stalled_.load() && n >= from_read_ && last_haptic_n_ >= min_force_n_) {
      stalled_.store(true);
      const std::int64_t give_up_ns = monotonic_ns() + 10'000'000'000;
      while (!supervisor_zero_.load() && monotonic_ns() < give_up_ns) {
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    }
    return inner_.read(time_s);
  }
  void write(const DeviceCommand& command) noexcept override {
    const bool haptic =
        reader_known_.load(std::memory_order_acquire) && std::this_thread::get_id() == reader_;
    const double f = command.force_world_n.norm();
    if (haptic) {
      last_haptic_n_ = f;
    } else if (stalled_.load() && f == 0.0) {
      supervisor_zero_.store(true);
    }
    inner_.write(command);
  }
  const DeviceProfile& profile() const noexcept override { return inner_.profile(); }
  DeviceStatus status() const noexcept override { return inner_.status(); }

  /// The stall happened and the supervisor ramped the force to zero during it.
  [[nodiscard]] bool stalled_to_zero() const { return supervisor_zero_.load(); }

 private:
  Device& inner_;
  std::uint64_t from_read_;
  double min_force_n_;
  std::uint64_t reads_ = 0;     // haptic thread only
  double last_haptic_n_ = 0.0;  // haptic thread only
  std::thread::id reader_;
  std::atomic<bool> reader_known_{false};
  std::atomic<bool> stalled_{false};
  std::atomic<bool> supervisor_zero_{false};
};

TEST(WorldHapticClient, SnapshotMatchesTheWorldExactlyAfterTheLoop) {
  World world(test::two_body_world());
  SimulatedDevice device(device_profile("omega3"), press_ball, 1.0);
  WorldHapticClient client(world);
  HapticLoopOptions o;
  o.max_cycles = 250;  // stop mid-press: a dent is there
  HapticLoop loop(device, client, o);
  loop.start();
  loop.wait();
  TripleBuffer<WorldSnapshot>& buffer = *client.snapshots();
  ASSERT_TRUE(buffer.update());
  const WorldSnapshot& s = buffer.read_slot();
  EXPECT_EQ(s.cycle, 249u);
  const std::size_t flat = world.flat_segment(BodyIndex{1}, LocalSegment{0}).index();
  const TriangleMesh& surface = world.surface(1, 0);
  ASSERT_EQ(s.positions_body[flat].size(), 3 * surface.vertices.size());
  std::size_t moved = 0;
  const auto rest = world.deflection(1, 0)->rest_positions();
  for (std::size_t v = 0; v < surface.vertices.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(s.positions_body[flat][3 * v + static_cast<std::size_t>(k)],
                static_cast<float>(surface.vertices[v][k]))
          << "vertex " << v;
    }
    moved += surface.vertices[v] != rest[v] ? 1 : 0;
  }
  EXPECT_GT(moved, 10u);  // the dent is in the snapshot, not just the rest shape
  EXPECT_GT(s.positions_version[flat], 0u);
  EXPECT_TRUE(s.positions_body[world.flat_segment(BodyIndex{0}, LocalSegment{0}).index()]
                  .empty());  // rigid: nothing to copy
  EXPECT_NEAR(s.deflection_m[flat], world.current_deflection_m(1, 0), 0.0);
  EXPECT_GT(s.contact_count, 0u);
  EXPECT_GT(s.tool_force_n[0], 0.0);
  EXPECT_EQ(s.tools[0].p_world, press_ball(0.249).p_world);
}

TEST(WorldHapticClient, ReaderThreadSeesConsistentSnapshotsAndHapticThreadDoesNotAllocate) {
  World world(test::two_body_world());
  SimulatedDevice device(device_profile("omega3"), press_ball, 1.0);
  WorldHapticClientOptions co;
  co.record_capacity = 1024;
  WorldHapticClient client(world, co);

  // Counts the haptic thread's allocations around the real client.
  test::AllocationCountingClient counting(client);

  HapticLoopOptions o;
  o.max_cycles = 700;  // the press and part of the recovery
  HapticLoop loop(device, counting, o);
  std::atomic<int> inconsistent{0};
  std::atomic<int> snapshots{0};
  std::uint64_t last_cycle = 0;
  loop.start();
  std::thread viewer([&] {
    while (loop.running()) {
      if (client.snapshots()->update()) {
        const WorldSnapshot& s = client.snapshots()->read_slot();
        // One cycle's data: the tool sits where that cycle's input put it.
        if (s.tools[0].p_world != s.input.p_world || s.cycle < last_cycle) {
          inconsistent.fetch_add(1);
        }
        last_cycle = s.cycle;
        snapshots.fetch_add(1);
      }
      std::this_thread::sleep_for(std::chrono::microseconds(300));
    }
  });
  std::size_t records = 0;
  while (loop.running() || client.records()->front() != nullptr) {
    while (const CycleRecord* r = client.records()->front()) {
      EXPECT_EQ(r->cycle, records);
      client.records()->pop();
      ++records;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  viewer.join();
  loop.wait();
  EXPECT_EQ(counting.allocations(), 0) << "the haptic thread allocated";
  EXPECT_EQ(inconsistent.load(), 0);
  EXPECT_GT(snapshots.load(), 50);
  EXPECT_EQ(records + client.dropped_records(), 700u);
}

// The shipped knee scene with its own scripted palpation device, snapshots and records on: the
// whole haptic cycle (device read, World::step, safety, write, publish) allocates nothing.
TEST(WorldHapticClient, KneeSceneWithItsScriptedDeviceAllocatesNothingOnTheHapticThread) {
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_procedural.json");
  World world(scene.world);
  auto device = make_scene_device(scene, world);
  WorldHapticClientOptions co;
  co.record_capacity = 8192;
  WorldHapticClient client(world, co);
  test::AllocationCountingClient counting(client);
  HapticLoopOptions o;
  o.max_cycles = 2500;  // the approach, the first press (medial ligament) and its release
  HapticLoop loop(*device, counting, o);
  loop.start();
  loop.wait();
  EXPECT_EQ(counting.allocations(), 0) << "the haptic thread allocated";
  EXPECT_GT(
      world.current_deflection_m(0, world.segment_count(0) - 1) +
          client.max_deflection_m()
              [world.flat_segment(BodyIndex{0}, LocalSegment{world.segment_count(0) - 1}).index()],
      0.001);  // it did press the skin
}

// Back from a pause with the device moved deep into the soft ball: no velocity from where the
// tool was before the pause (no damping spike: the force is the spring's, k·x), and the loop is
// asked to bring the force back gradually.
TEST(WorldHapticClient, ResumingAfterAPauseHasNoDampingSpikeAndAsksForASoftStart) {
  World world(test::two_body_world());
  WorldHapticClient client(world);
  DeviceInput in;
  in.p_world = Vec3(0.2, 0.0, 0.05);  // well above the ball (top at z = 0)
  (void)client.step(in, 0.001);
  EXPECT_FALSE(client.take_soft_start());
  client.set_paused(true);
  in.p_world = Vec3(0.2, 0.0, -0.005 + 0.004);  // meanwhile 5 mm into the ball
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(client.step(in, 0.001).force_world_n.norm(), 0.0);
  }
  client.set_paused(false);
  const double f = client.step(in, 0.001).force_world_n.norm();
  EXPECT_TRUE(client.take_soft_start());
  EXPECT_FALSE(client.take_soft_start());  // once
  // 300 N/m · 5 mm = 1.5 N; 50 mm in 1 ms through the damping floor would add ~15 N.
  EXPECT_NEAR(f, 1.5, 0.1);
}

// Records are numbered by the cycles that stepped the world, not by the loop's cycle index: a
// pause in the middle of a run (cycles that step nothing and record nothing) leaves no gap, so a
// recording across it replays frame for frame (a replay numbers its frames 0, 1, 2, ...).
TEST(WorldHapticClient, RecordsAreNumberedByTheCyclesThatStepped) {
  World world(test::two_body_world());
  WorldHapticClientOptions co;
  co.publish_snapshots = false;
  co.record_capacity = 256;
  WorldHapticClient client(world, co);
  std::uint64_t stepped = 0;
  for (std::uint64_t i = 0; i < 150; ++i) {  // the loop's cycles
    client.set_paused(i >= 50 && i < 80);
    const DeviceInput in = press_ball(0.001 * static_cast<double>(stepped));
    const DeviceCommand out = client.step(in, 0.001);
    HapticCycle cycle;
    cycle.index = i;
    cycle.time_s = 0.001 * static_cast<double>(i);
    cycle.input = &in;
    cycle.output = &out;
    client.after_cycle(cycle);
    stepped += client.paused() ? 0 : 1;
  }
  ASSERT_EQ(stepped, 120u);
  std::uint64_t expected = 0;
  while (const CycleRecord* r = client.records()->front()) {
    EXPECT_EQ(r->cycle, expected) << "the record after " << expected << " stepped cycle(s)";
    EXPECT_EQ(r->input.time_s, 0.001 * static_cast<double>(expected));
    client.records()->pop();
    ++expected;
  }
  EXPECT_EQ(expected, 120u);
}

// Counts which of its calls came in which cycle (a served world publishes from them).
class CountingObserver final : public WorldCycleObserver {
 public:
  void before_step(World& /*world*/) noexcept override { ++before; }
  void after_step(const World& /*world*/, const HapticCycle& cycle) noexcept override {
    ++stepped;
    last_stepped_cycle = cycle.index;
  }
  void after_paused_cycle(const World& /*world*/, const HapticCycle& cycle) noexcept override {
    ++paused;
    last_paused_cycle = cycle.index;
  }
  std::uint64_t before = 0;
  std::uint64_t stepped = 0;
  std::uint64_t paused = 0;
  std::uint64_t last_stepped_cycle = 0;
  std::uint64_t last_paused_cycle = 0;
};

TEST(WorldHapticClient, TheObserverHearsOfEveryCycleSteppedOrPaused) {
  World world(test::two_body_world());
  CountingObserver observer;
  WorldHapticClientOptions co;
  co.publish_snapshots = false;
  co.observer = &observer;
  WorldHapticClient client(world, co);
  for (std::uint64_t i = 0; i < 100; ++i) {
    client.set_paused(i >= 30 && i < 70);
    const DeviceInput in = press_ball(0.001 * static_cast<double>(i));
    const DeviceCommand out = client.step(in, 0.001);
    HapticCycle cycle;
    cycle.index = i;
    cycle.input = &in;
    cycle.output = &out;
    client.after_cycle(cycle);
  }
  EXPECT_EQ(observer.before, 60u);
  EXPECT_EQ(observer.stepped, 60u);
  EXPECT_EQ(observer.paused, 40u);
  EXPECT_EQ(observer.last_paused_cycle, 69u);
  EXPECT_EQ(observer.last_stepped_cycle, 99u);
}

TEST(WorldHapticClient, ResetAndPauseReachTheSnapshot) {
  World world(test::two_body_world());
  SimulatedDevice device(device_profile("omega3"), press_ball, 1.0);
  WorldHapticClient client(world);
  HapticLoopOptions o;
  o.max_cycles = 200;
  {
    HapticLoop loop(device, client, o);
    loop.start();
    loop.wait();
  }
  ASSERT_GT(world.current_deflection_m(1, 0), 0.0);
  client.request_reset();
  client.set_paused(true);
  HapticLoop again(device, client, o);
  again.start();
  again.wait();
  ASSERT_TRUE(client.snapshots()->update());
  const WorldSnapshot& s = client.snapshots()->read_slot();
  const std::size_t flat = world.flat_segment(BodyIndex{1}, LocalSegment{0}).index();
  const auto rest = world.deflection(1, 0)->rest_positions();
  for (std::size_t v = 0; v < rest.size(); ++v) {
    ASSERT_EQ(s.positions_body[flat][3 * v + 2], static_cast<float>(rest[v].z()));
  }
  EXPECT_EQ(s.output.force_world_n.norm(), 0.0);  // paused: no force
}

TEST(Session, RealtimeRunAccountsTheSameContactsAsAnInlineRun) {
  const DeviceProfile& omega = device_profile("omega3");
  SessionOptions options;
  options.duration_s = 0.8;
  SessionSummary inline_run;
  {
    World world(test::two_body_world());
    SimulatedDevice device(omega, press_ball, 1.0);
    inline_run = run_session(world, device, options);
  }
  World world(test::two_body_world());
  SimulatedDevice device(omega, press_ball, 1.0);
  options.realtime = true;
  const SessionSummary rt = run_session(world, device, options);
  ASSERT_TRUE(rt.realtime.has_value());
  EXPECT_FALSE(inline_run.realtime.has_value());
  EXPECT_EQ(rt.steps + rt.realtime->dropped_records, 800u);
  EXPECT_EQ(rt.realtime->dropped_records, 0u);
  EXPECT_GT(rt.realtime->rate_hz, 0.0);
  ASSERT_EQ(rt.segments.size(), inline_run.segments.size());
  // The simulated device plays by simulation time: the same inputs, the same world, the same
  // contacts and deflection, whatever the thread's timing.
  for (std::size_t i = 0; i < rt.segments.size(); ++i) {
    EXPECT_EQ(rt.segments[i].contacts, inline_run.segments[i].contacts);
    EXPECT_EQ(rt.segments[i].peak_force_n, inline_run.segments[i].peak_force_n);
    EXPECT_EQ(rt.segments[i].max_deflection_m, inline_run.segments[i].max_deflection_m);
  }
  EXPECT_EQ(rt.pop_throughs, 0u);
  if (rt.realtime->ramp_cycles == 0) {  // a stall on a loaded machine would scale the output
    EXPECT_EQ(rt.tools[0].peak_force_n, inline_run.tools[0].peak_force_n);
  }
  const std::string text = format_session_summary(rt);
  EXPECT_NE(text.find("real time:"), std::string::npos) << text;
}

// A real-time run's recording (frames handed off the haptic thread through the ring) replays
// offline bit for bit: the same inputs give the same world, contacts and commands — also when the
// loop stalled mid-press, so that the supervisor ramped the output to zero and it came back over
// the ramp time (wall-clock safety the offline replay does not redo: the recording holds the
// world's command clamped to the device, the summary the output).
TEST(Session, RealtimeRecordingReplaysBitForBitOffline) {
  const DeviceProfile& omega = device_profile("omega3");
  const auto path = std::filesystem::temp_directory_path() /
                    ("hapsim_rt_rec_" + std::to_string(::getpid()) + ".rec");
  const auto again = std::filesystem::temp_directory_path() /
                     ("hapsim_rt_rec_again_" + std::to_string(::getpid()) + ".rec");
  SessionSummary rt;
  {
    World world(test::two_body_world());
    SimulatedDevice simulated(omega, press_ball, 1.0);
    StallingDevice device(simulated, 100, 0.2);                 // mid-press
    SessionRecorder recorder(path, world.content_hash(), 256);  // flushed many times meanwhile
    SessionOptions o;
    o.duration_s = 0.6;
    o.realtime = true;
    o.recorder = &recorder;
    rt = run_session(world, device, o);
    recorder.close();
    EXPECT_TRUE(device.stalled_to_zero());
  }
  ASSERT_TRUE(rt.realtime.has_value());
  EXPECT_GE(rt.realtime->stall_events, 1u);
  EXPECT_GT(rt.realtime->ramp_cycles, 0u);
  EXPECT_EQ(rt.recorded_frames, 600u);
  EXPECT_EQ(rt.recording_dropped_frames, 0u);
  const Recording original = read_recording(path);
  ASSERT_EQ(original.frames.size(), 600u);
  World world(test::two_body_world());
  ReplayDevice replay(omega, original.frames);
  SessionRecorder recorder(again, world.content_hash(), 256);
  SessionOptions o;
  o.duration_s = 0.6;
  o.recorder = &recorder;
  (void)run_session(world, replay, o);
  recorder.close();
  const RecordingDifference d = compare_recordings(original, read_recording(again));
  EXPECT_TRUE(d.identical) << d.message;
  std::filesystem::remove(path);
  std::filesystem::remove(again);
}

// `hapsim run scenes/knee_procedural.json --realtime --record F` then `--replay F`: the shipped
// scene with its palpation script on the real-time loop, stalled once while the fingertip presses,
// replays bit for bit the way the command replays it (make_run_setup with the recording, an inline
// run).
TEST(Session, RealtimeKneeRecordingReplaysBitForBitAfterAStall) {
  const SceneDescription scene =
      load_scene(std::filesystem::path(HAPSIM_SOURCE_DIR) / "scenes" / "knee_procedural.json");
  const auto path = std::filesystem::temp_directory_path() /
                    ("hapsim_rt_knee_" + std::to_string(::getpid()) + ".rec");
  RunSetup setup = make_run_setup(scene, DeviceChoice::scene_script());
  StallingDevice device(*setup.device, 1000, 0.5);  // the first press starts at ~1 s
  SessionSummary rt;
  {
    SessionRecorder recorder(path, setup.world->content_hash(), 8192);
    SessionOptions o;
    o.duration_s = 1.5;
    o.dt_s = setup.scene.run.dt_s;
    o.realtime = true;
    o.recorder = &recorder;
    rt = run_session(*setup.world, device, o);
    recorder.close();
  }
  EXPECT_TRUE(device.stalled_to_zero());
  ASSERT_TRUE(rt.realtime.has_value());
  EXPECT_GE(rt.realtime->stall_events, 1u);
  EXPECT_GT(rt.realtime->ramp_cycles, 0u);
  EXPECT_EQ(rt.recording_dropped_frames, 0u);
  EXPECT_TRUE(test::replays_bit_for_bit(scene, path));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace hapsim
