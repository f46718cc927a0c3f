// The device host's side of each haptic cycle (`hapsim device`, SPEC §8): the simulation is far
// away, so the 1 kHz loop renders force from the newest local contact model per tool, evaluated
// at the device's own fresh position, and tells the simulation where the device is and what it
// rendered. One cycle, allocation-free and non-blocking:
//   1. the device's input (the loop read it) gets the next state sequence and a velocity;
//   2. local models that arrived are taken and gated (net/local_model_gate.h); accepted ones go
//      to their tool's renderer (device/local_model_renderer.h: blend, validity radius,
//      push-only, clamp, stale fade by this host's clock);
//   3. each tool's force is rendered where the tool is now: the model's x0 moved by how far the
//      device moved since the state the model answered (exact for a probe; for a glove's
//      fingertip it leaves out the finger's own flexion since then);
//   4. a passivity observer per tool (device/passivity_observer.h, Hannaford & Ryu) adds damping
//      once the rendered contact has given out more energy than it took in (reset in free
//      space: a finished contact's absorbed energy licenses nothing in the next one);
//   5. the force's change per cycle is limited (a step from a bad model is felt as a ramp);
//   6. after the device write, the state (input, velocity, what was rendered after the loop's
//      safety layer) goes out on the DeviceState topic.
// A rig's master arm (DeviceHostOptions::rig) renders its carried tool's model where the slave's
// target puts the tool, and a grasping rig's pads' models where it puts the pads, and feels the
// force as joint torques through the master's Jᵀ and the pads' grip on its fingers.
// `raw` mode renders the newest model's f0 as it came, as the knee paper sent raw forces: for
// comparison only, unstable beyond a few ms of delay (docs/benchmarks.md).
// Models that answer a state this host did not send (sequence 0: the simulation's own script)
// are never rendered.
#pragma once

#include "hapsim/device/local_model_renderer.h"
#include "hapsim/device/passivity_observer.h"
#include "hapsim/net/device_state_codec.h"
#include "hapsim/net/force_mode.h"
#include "hapsim/net/link_shim.h"
#include "hapsim/net/local_model_gate.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/rig/rig_controller.h"
#include "hapsim/runtime/haptic_loop.h"
#include "hapsim/runtime/latency_histogram.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

namespace hapsim::net {

struct DeviceHostOptions {
  std::uint16_t device_id = 0;
  ForceMode mode = ForceMode::kLocalModel;
  /// The renderers' options; max_force_n is the tip force's rating.
  LocalModelRenderOptions render;
  /// The rating of a finger actuator (a force glove), for the tools on a finger; 0: the tip's.
  double max_finger_force_n = 0.0;
  /// Largest change of a tool's force per second (N/s): 10 N in 5 ms.
  double max_force_rate_n_per_s = 2000.0;
  LocalModelLimits limits;
  /// The last guard of the local-model mode (raw mode only observes: it is the comparison).
  PassivityObserverOptions passivity;
  /// `--link-shim`: received models go through a simulated link first (its clock: this host's
  /// seconds since the client was made). Empty: none.
  std::optional<LinkShimOptions> link;
  /// The sequence this host numbers its states from (the first state is one more). 0: drawn at
  /// random, so a second host on the same device id (a name already taken) tells the models
  /// answering the other's states from its own (DeviceHostStatus::models_other_device_host).
  std::uint64_t state_sequence_base = 0;
  /// A served rig (a scene's "rig"): this host is its master arm. Its one tool is the tool the
  /// slave carries, placed each cycle where the slave's target puts it for the master's joints
  /// (RigController::flange_point_target_world, `rig_tool_flange_m` its centre in the flange
  /// frame), and the force rendered there goes to the master's joints as the rig's own command
  /// does (RigController::master_command): joint torques, not a tip force. A rig that grasps a
  /// ball (grasps_ball) has its two pads' models served after its tools (net/model_publisher.h):
  /// each is rendered where the slave's target puts that pad (RigController::
  /// pad_centre_target_world), their sum joins the tool's force at the slave's tool and their push
  /// is the grasp on the master's fingers. Null: a probe or glove.
  std::shared_ptr<const RigController> rig;
  Vec3 rig_tool_flange_m = Vec3::Zero();
};

/// `options.render` with a finger actuator's rating as its force limit (when one is given).
[[nodiscard]] LocalModelRenderOptions finger_render_options(
    const DeviceHostOptions& options) noexcept;

/// What the simulation host says it runs (from its SceneInfo): set from any thread, applied by
/// the haptic thread at its next cycle.
struct ServedScene {
  std::uint64_t scene_hash = 0;
  std::uint64_t serve_id = 0;
  std::uint16_t tool_count = 0;
  /// Per tool: the device finger it drives (-1: the tip force).
  std::array<std::int16_t, kMaxFingers> tool_finger{-1, -1, -1, -1, -1};
};

/// Figures of the running host, readable from any thread.
struct DeviceHostStatus {
  std::uint64_t cycles = 0;
  std::uint64_t states_published = 0;
  std::uint64_t models_accepted = 0;
  /// Models answering no state of this host (the simulation's script), not rendered.
  std::uint64_t models_not_ours = 0;
  /// Models for this device id answering states another device host sent (this host's device
  /// id, or its name, is taken by another host that the simulation follows); refused, counted
  /// under kOtherHost too.
  std::uint64_t models_other_device_host = 0;
  VerdictCounts verdicts{};
  /// monotonic_ns() of the newest accepted model and of the last cycle with a non-zero force
  /// (0: never).
  std::int64_t last_model_ns = 0;
  std::int64_t last_force_ns = 0;
  /// What this cycle rendered: the largest over tools, or a rig master's force at the slave's
  /// tool (its carried tool's and its pads' together).
  double force_n = 0.0;
  /// What the cycle that took the newest model rendered (largest over tools).
  double force_at_last_model_n = 0.0;
  /// The same two moments as cycles of the device loop (this client's steps): how long a fade
  /// took counted in cycles, not in a duration a loaded machine stretches.
  std::uint64_t last_model_cycle = 0;
  std::uint64_t last_force_cycle = 0;
  double peak_force_n = 0.0;  ///< over the run
  /// A rig's master (DeviceHostOptions::rig): its arm's largest joint torque over the run, N·m,
  /// and the largest grasp its fingers rendered (the pads' mean push), N.
  double peak_joint_torque_nm = 0.0;
  double peak_grasp_force_n = 0.0;
  /// A grasping rig's master: the mean force at the slave's tool it rendered over the cycles both
  /// pads pressed the ball (what it felt of the carried ball), and how many cycles that was.
  double mean_held_force_n = 0.0;
  std::uint64_t held_cycles = 0;
  std::uint64_t rate_limited_cycles = 0;
  std::uint64_t scene_changes = 0;
  /// Models the receive-side link shim lost (any reason) and delivered (zero without one).
  std::uint64_t link_lost = 0;
  std::uint64_t link_delivered = 0;
  /// Cycles the passivity controller added damping (any tool), and the energy it took out, J.
  std::uint64_t passivity_cycles = 0;
  double passivity_dissipated_j = 0.0;
  /// Device → simulation → device: from writing a state to taking the first model that
  /// answered it (this host's clock at both ends), microseconds.
  LatencyPercentilesUs round_trip_us;
};

class DeviceHostClient final : public HapticClient {
 public:
  DeviceHostClient(const Participant& participant, const DeviceHostOptions& options);

  /// Any thread: the served scene changed (a new simulation host, or a restarted one).
  void set_scene(const ServedScene& scene) noexcept;

  /// haptic path
  const DeviceCommand& step(const DeviceInput& input, double dt_s) override;
  /// haptic path
  void after_cycle(const HapticCycle& cycle) noexcept override;

  [[nodiscard]] DeviceHostStatus status() const noexcept;

 private:
  static constexpr std::size_t kHistory = 1024;  ///< > the gate's max_age_cycles

  void apply_scene() noexcept;
  void take_models(double now_s, std::int64_t now_ns) noexcept;
  /// `writer`: the DDS writer the model came from (0: not known, as through the link shim).
  void admit_model(const hapsim_msg_LocalModel& m, double now_s, std::int64_t now_ns,
                   dds_instance_handle_t writer) noexcept;
  /// The points that move with the device, each with its own history: the device's own (a rig
  /// master's: its carried tool's), then a grasping rig's two pads.
  static constexpr std::size_t kPoints = 3;
  /// Key `key`'s force where point `point` is now (its model's x0 moved by how far the point
  /// moved since the state the model answered). haptic path
  [[nodiscard]] Vec3 key_force(std::size_t key, std::size_t point, double now_s) noexcept;
  /// key_force through key's passivity observer and the force rate limit. haptic path
  [[nodiscard]] Vec3 render_key(std::size_t key, std::size_t point, double dt_s, double now_s,
                                bool& limited, std::uint64_t& acted, double& dissipated_j) noexcept;

  DeviceHostOptions options_;
  TopicReader<hapsim_msg_LocalModel> models_in_;
  TopicWriter<hapsim_msg_DeviceState> states_out_;
  static constexpr std::size_t kLinkCapacity = 1024;  ///< 200 ms of 5 fingers' models
  std::unique_ptr<LinkShim<hapsim_msg_LocalModel, kLinkCapacity>> link_;
  double link_epoch_s_ = 0.0;
  std::atomic<std::uint64_t> link_lost_{0};
  std::atomic<std::uint64_t> link_delivered_{0};

  // Set by set_scene (any thread), applied by the haptic thread.
  std::atomic<std::uint64_t> pending_hash_{0};
  std::atomic<std::uint64_t> pending_serve_id_{0};
  std::atomic<std::uint64_t> pending_layout_{0};  ///< tool count and fingers, packed
  std::atomic<std::uint64_t> pending_version_{0};
  std::uint64_t applied_version_ = 0;

  // Haptic thread only.
  ServedScene scene_;
  LocalModelGate gate_;
  std::array<LocalModelRenderer, kMaxFingers> renderers_;
  std::array<PassivityObserver, kMaxFingers> passivity_;
  std::array<LocalContactModel, kMaxFingers> raw_models_{};
  std::array<double, kMaxFingers> raw_received_s_{};
  std::array<Vec3, kMaxFingers> previous_force_n_{};
  std::array<std::array<Vec3, kPoints>, kHistory> p_history_m_{};
  /// monotonic_ns() when each state went out (by sequence), and whether a model answered it.
  std::array<std::int64_t, kHistory> state_sent_ns_{};
  std::array<bool, kHistory> answered_{};
  /// A rig's master: the carried tool's force this cycle's torques render (the push its tissue
  /// takes), and whether its pads' models are served (grasps_ball).
  Vec3 rig_force_world_n_ = Vec3::Zero();
  bool rig_grasps_ = false;
  std::uint64_t sequence_base_ = 0;  ///< states are numbered from sequence_base_ + 1
  std::uint64_t sequence_ = 0;
  /// The simulation host followed: the writer of the first model accepted for the current scene,
  /// until it is silent for the renderer's fade (0: none yet). Another writer's models meanwhile
  /// are refused (kOtherHost): a second serve on the session cannot take the device over.
  dds_instance_handle_t followed_writer_ = 0;
  std::int64_t followed_seen_ns_ = 0;
  std::array<Vec3, kPoints> p_m_{};  ///< this cycle's
  std::array<Vec3, kPoints> v_m_per_s_{};
  DeviceCommand command_;
  DeviceStateSample state_;

  // Published for status().
  std::atomic<std::uint64_t> cycles_{0};
  std::atomic<std::uint64_t> states_published_{0};
  std::atomic<std::uint64_t> models_accepted_{0};
  std::atomic<std::uint64_t> models_not_ours_{0};
  std::atomic<std::uint64_t> models_other_device_host_{0};
  std::array<std::atomic<std::uint64_t>, kSampleVerdicts> verdicts_{};
  std::atomic<std::int64_t> last_model_ns_{0};
  std::atomic<std::int64_t> last_force_ns_{0};
  std::atomic<std::uint64_t> last_model_cycle_{0};
  std::atomic<std::uint64_t> last_force_cycle_{0};
  std::atomic<double> force_n_{0.0};
  std::atomic<double> force_at_last_model_n_{0.0};
  bool took_model_ = false;  ///< this cycle accepted a model (haptic thread)
  std::atomic<double> peak_force_n_{0.0};
  std::atomic<double> peak_joint_torque_nm_{0.0};
  std::atomic<double> peak_grasp_force_n_{0.0};
  double mean_held_force_n_ = 0.0;  ///< haptic thread's running mean; published below
  std::uint64_t held_cycles_ = 0;
  std::atomic<double> published_mean_held_force_n_{0.0};
  std::atomic<std::uint64_t> published_held_cycles_{0};
  std::atomic<std::uint64_t> rate_limited_{0};
  std::atomic<std::uint64_t> scene_changes_{0};
  LatencyHistogram round_trip_us_;
  std::atomic<std::uint64_t> passivity_cycles_{0};
  std::atomic<double> passivity_dissipated_j_{0.0};
};

}  // namespace hapsim::net
