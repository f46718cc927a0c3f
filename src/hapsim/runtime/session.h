// One unattended run of a world driven by a device (architecture.md#real-time,
// architecture.md#scenes): the deterministic step at a fixed dt, as fast as it goes (offline) or on
// an absolute 1 kHz deadline (--realtime), with the device safety layer between the world and the
// device, an optional recorder, and the figures a user wants at the end: contacts and deflection
// per segment, forces per tool, pop-throughs, force-limit violations and the cost of a step.
#pragma once

#include "hapsim/core/progress.h"
#include "hapsim/core/statistics.h"
#include "hapsim/device/device.h"
#include "hapsim/device/recording.h"
#include "hapsim/runtime/haptic_loop.h"
#include "hapsim/runtime/world_haptic_client.h"
#include "hapsim/world/world.h"

#include <atomic>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hapsim {

/// The most steps one session runs: as fast as possible, 1e8 (27.8 h at 1 kHz; the step-cost
/// samples alone take 800 MB); in real time, 1e11 (a served world "until stopped" is a year).
/// run_session() refuses more, so a dt_s of 1e-9 or a duration of 1e300 s is an error, not a
/// bad_alloc or an integer overflow.
[[nodiscard]] constexpr double max_session_steps(bool realtime) {
  return realtime ? 1e11 : 1e8;
}

struct SessionOptions {
  /// Simulated seconds to run (> 0).
  double duration_s = 10.0;
  double dt_s = 0.001;
  /// Run on the real-time haptic thread (haptic_loop.h): an absolute 1 kHz deadline, SCHED_FIFO
  /// when permitted, the supervisor's stall ramp; the bookkeeping below runs on this thread from
  /// a lock-free ring of cycle records. Otherwise the cycles run inline as fast as they go.
  bool realtime = false;
  /// Real-time loop settings (period and cycle count are set from dt_s and duration_s).
  HapticLoopOptions loop;
  /// Check every step, outside the timed step, that no tool's proxy centre entered a closed
  /// proxy segment, against an exact query built independently of the world's method.
  bool check_pop_through = true;
  /// Receives every cycle (input, command after safety, contacts). Not owned; may be null.
  SessionRecorder* recorder = nullptr;
  /// A teleoperation rig's pick-and-place target: where the ball should come to rest (the
  /// summary then reports how far from it the ball ended).
  std::optional<Vec3> teleop_target_world;
  ProgressFn progress;
  /// Real-time runs only: called on the haptic thread around every step (a served world
  /// publishes from it). Not owned; may be null.
  WorldCycleObserver* observer = nullptr;
  /// Real-time runs only: also publish a viewer snapshot every cycle; `on_snapshots` gets their
  /// buffer before the loop starts and null once the loop has stopped, before the buffer goes
  /// (both calls on the calling thread: a reader elsewhere must be done with it on return).
  std::function<void(TripleBuffer<WorldSnapshot>*)> on_snapshots;
  /// Real-time runs only: the loop's client (to pause it, reset the world or change a material
  /// from another thread: WorldHapticClient's thread-safe requests) before the loop starts, and
  /// null once it has stopped, before the client goes (both calls on the calling thread).
  std::function<void(WorldHapticClient*)> on_client;
  /// When this becomes true the run ends after the current cycle (a served world runs until
  /// stopped; SIGINT stops `hapsim run`), and the summary covers the cycles run. Not owned; may be
  /// null.
  const std::atomic<bool>* stop = nullptr;
  /// Inline runs only: called after every cycle's bookkeeping with the cycle index (between
  /// cycles, on the stepping thread: may read the world, e.g. to render a snapshot).
  std::function<void(std::size_t cycle)> after_cycle;
  /// Every cycle's record, after the run's own bookkeeping took it (inline: on the stepping
  /// thread; real time: on the calling thread, from the ring — never the haptic thread). An
  /// assessment scores a session from these (training/assessment_scorer.h).
  std::function<void(const CycleRecord&)> on_record;
};

/// Step costs, microseconds.
using StepTimingUs = SampleSummary;

/// Forces as the device renders them (after the safety layer's clamp): a finger tool's actuator
/// force, or the tool's share of the tip force.
struct ToolSummary {
  std::string name;
  double peak_force_n = 0.0;
  /// Mean force magnitude over the steps in which the tool touched something.
  double mean_force_n = 0.0;
  std::size_t contact_steps = 0;
};

struct SegmentSummary {
  std::string body;
  std::string name;
  /// Tool-steps in contact with this segment.
  std::size_t contacts = 0;
  /// Largest contact force the world computed on this segment (before the device clamp).
  double peak_force_n = 0.0;
  double max_deflection_m = 0.0;
};

/// How the real-time loop kept time (SessionOptions::realtime).
struct RealtimeSummary {
  double rate_hz = 0.0;
  /// |period − dt|, microseconds.
  LatencyPercentilesUs period_jitter_us;
  /// Periods longer than 2·dt.
  std::size_t missed_deadlines = 0;
  bool realtime_priority = false;
  std::size_t stall_events = 0;
  std::size_t ramp_cycles = 0;
  std::size_t failed_steps = 0;
  /// Writes the haptic thread cut itself for a gap since its previous write beyond the grace
  /// (HapticLoopStatus::resume_gaps: a freeze of the whole process, a long preemption).
  std::size_t resume_gaps = 0;
  /// HapticLoopStatus::memory_locked and haptic_page_faults.
  bool memory_locked = false;
  long haptic_page_faults = -1;
  /// Cycle records the bookkeeping could not keep up with (not accounted, not recorded).
  std::size_t dropped_records = 0;
  /// Cycles the loop ran, and those a ramp capped for lateness alone
  /// (HapticLoopStatus::late_ramp_cycles).
  std::size_t cycles = 0;
  std::size_t late_ramp_cycles = 0;
};

/// What a teleoperation rig did over the run (the pick-and-place of paper 000).
struct TeleopSummary {
  /// The rig picks a ball (the pick-and-place scenes); without one (tele-palpation) the grasp and
  /// ball figures stay at their defaults.
  bool has_ball = false;
  bool has_sheet = false;
  bool grasped = false;
  double grasp_time_s = -1.0;    ///< first grasp (-1: never)
  double release_time_s = -1.0;  ///< first release after it (-1: never)
  double ball_lift_m = 0.0;      ///< highest the ball rose above its start
  double peak_grasp_force_n = 0.0;
  double max_sheet_deflection_m = 0.0;
  double max_slave_tracking_error_m = 0.0;
  /// Steps the slave's joints were held to their speed or acceleration limits (SlaveStep): the
  /// slave catching up with a master that moved faster than it can follow, or that stalled and
  /// jumped (a served master's late states). 0 in a smooth scripted run.
  std::size_t slave_limited_steps = 0;
  std::size_t nonfinite_ball_steps = 0;
  /// Slave collisions (TeleopStepResult::slave_collisions): steps with one, their sum over the
  /// run, the first one's time (-1: none) and the bodies involved (the slave's and what it hit).
  std::size_t slave_collision_steps = 0;
  std::size_t slave_collisions = 0;
  double first_slave_collision_s = -1.0;
  std::vector<std::string> slave_collision_bodies;
  Vec3 ball_final_world = Vec3::Zero();
  /// The largest force at the slave's tool (TeleopStepResult::tool_force_world_n) and the largest
  /// joint torque the master's arm motors were asked for, over the run.
  double peak_tool_force_n = 0.0;
  double peak_master_torque_nm = 0.0;
  /// The mean force at the slave's tool over the steps the grasp held (the ball's weight and its
  /// carry's accelerations, through the pads), and how many steps that was: what the master felt
  /// of the carried ball, steadier than a peak a single jerk of the slave sets.
  double mean_held_tool_force_n = 0.0;
  std::size_t held_steps = 0;
  /// With SessionOptions::teleop_target_world: the ball's final distance from it.
  std::optional<double> target_error_m;
  /// Grasped, released, the ball finite and (with a target) within 5 mm of it.
  [[nodiscard]] bool placed() const;
};

/// What a dynamic body did over the run.
struct BodySummary {
  std::string name;
  Vec3 start_world = Vec3::Zero();  ///< its body frame's origin
  Vec3 final_world = Vec3::Zero();
  double max_rise_m = 0.0;  ///< highest it rose above its start
  double final_speed_m_per_s = 0.0;
  /// The bodies it touches at the end (what it rests on).
  std::vector<std::string> touching_at_end;
  std::size_t nonfinite_steps = 0;
};

/// What a sheet did over the run.
struct SheetSummary {
  std::string name;
  double max_depth_m = 0.0;
  double final_depth_m = 0.0;
};

/// What the FEM bodies did over the run (world/fem_coupling.h).
struct FemSummary {
  std::uint64_t updates = 0;       ///< FEM updates run
  std::uint64_t adopted = 0;       ///< adopted by the haptic path
  std::uint64_t late_adopted = 0;  ///< adopted after their due step (real time: the FEM was late)
  std::uint64_t skipped_launches = 0;
  std::uint64_t period_steps = 0;  ///< haptic steps per FEM step
  /// Wall-clock cost of one update (every FEM body), ms: p50, p99, max.
  double update_ms_p50 = 0.0;
  double update_ms_p99 = 0.0;
  double update_ms_max = 0.0;
  /// Per FEM body: its name, tets, nodes, and its largest node displacement at the end, m.
  struct Body {
    std::string name;
    std::size_t tets = 0;
    std::size_t nodes = 0;
    std::string elasticity;
    double final_max_displacement_m = 0.0;
  };
  std::vector<Body> bodies;
  /// FEM updates that threw (run inside the step, or the FEM thread's, which then stops), and
  /// the first one's message.
  std::uint64_t failures = 0;
  std::string error;
};

/// The FEM figures of `world` after a run (nullopt without FEM bodies).
[[nodiscard]] std::optional<FemSummary> fem_summary(const World& world);

/// A material the world renders softer than described: its stiffness is above the device's
/// rated maximum (WorldOptions::max_stiffness_n_per_m, which run assembly sets from the device
/// profile), so contact on it uses the maximum instead.
struct StiffnessClamp {
  std::string material;
  double stiffness_n_per_m = 0.0;  ///< as described
  double clamped_n_per_m = 0.0;    ///< as rendered: the device's rated maximum
};

/// The materials of `world` used by at least one segment whose stiffness its options clamp, in
/// the description's order (empty when nothing is clamped).
[[nodiscard]] std::vector<StiffnessClamp> stiffness_clamps(const World& world);

struct SessionSummary {
  std::size_t steps = 0;
  /// SessionOptions::stop ended the run before its last cycle (the figures are of `steps`).
  bool interrupted = false;
  double simulated_s = 0.0;
  double wall_s = 0.0;
  StepTimingUs step_us;
  /// Times a tool's proxy centre went into a closed proxy segment (once per entry, not per step
  /// inside), plus proxies lost and tools that left a penalty segment through its far side
  /// (must be 0).
  std::size_t pop_throughs = 0;
  /// Times a tool's proxy was already inside a closed proxy segment when it was placed (the first
  /// step, or a jump: a reset, a device placed inside): not a pop-through, said once.
  std::size_t started_inside = 0;
  /// The first of those: "tool 'tip' in block/block at 0.000 s".
  std::string started_inside_first;
  /// Deepest the proxy sphere ever reached into a proxy segment, metres (tolerance-sized; not
  /// while it was placed inside).
  double max_proxy_penetration_m = 0.0;
  std::vector<ToolSummary> tools;
  std::vector<SegmentSummary> segments;
  /// Commands sent above the device's rated force (after the safety layer: must be 0).
  std::size_t max_force_limit_violations = 0;
  /// Cycles where the safety layer had to clamp the world's command to the device.
  std::size_t clamped_cycles = 0;
  std::size_t nonfinite_commands = 0;
  double peak_command_force_n = 0.0;
  std::size_t dropped_contacts = 0;
  std::size_t recorded_frames = 0;
  std::size_t recording_dropped_frames = 0;
  /// Why the recording stopped before the run did (a full disk): the run goes on, its summary
  /// and JSON are still written, and the run fails with this. Empty when it did not.
  std::string recording_error;
  /// Realtime only: periods longer than two nominal periods.
  std::size_t missed_deadlines = 0;
  std::optional<RealtimeSummary> realtime;
  /// Worlds with a teleoperation rig.
  std::optional<TeleopSummary> teleop;
  /// Dynamic bodies (the first kMaxCycleDynamicBodies) and sheets (the first kMaxCycleSheets).
  std::vector<BodySummary> bodies;
  std::vector<SheetSummary> sheets;
  /// Materials rendered at the device's rated stiffness instead of their own (stiffness_clamps).
  std::vector<StiffnessClamp> stiffness_clamps;
  /// Worlds with FEM bodies.
  std::optional<FemSummary> fem;
};

/// Runs `world` with `device` for options.duration_s. Throws hapsim::Error on bad options.
[[nodiscard]] SessionSummary run_session(World& world, Device& device,
                                         const SessionOptions& options);

/// The recorder a command's `--record FILE` writes a session through (`hapsim run`, `hapsim
/// serve`): the header names `world`'s content hash and `scene_file`; 8192 frames of buffer
/// (slack for a slow disk) whose overflow is dropped and counted, never a blocking write on the
/// haptic thread; run_session() flushes it every 100 ms of the session, off the haptic thread.
/// Throws hapsim::Error when the file cannot be created.
[[nodiscard]] std::unique_ptr<SessionRecorder> make_session_recorder(
    const std::filesystem::path& path, const World& world, const std::filesystem::path& scene_file);

/// After run_session(): writes the recording's last block and closes it. A write that fails (a
/// full disk) becomes summary.recording_error, unless the run already set one: the summary says
/// it in one line ("recording STOPPED early: …") and run_failures() fails the run with it.
void finish_session_recording(SessionRecorder& recorder, SessionSummary& summary);

/// The real-time figures of a finished loop; `dropped_records`: records its consumer missed.
[[nodiscard]] RealtimeSummary realtime_summary(const HapticLoopStatus& status,
                                               std::size_t dropped_records);
/// The "real time: …" line(s) of a summary.
[[nodiscard]] std::string format_realtime_summary(const RealtimeSummary& realtime);

/// Short human summary (a dozen lines), with one line naming the clamped materials, if any.
[[nodiscard]] std::string format_session_summary(const SessionSummary& summary);

}  // namespace hapsim
