// The simulation host's side of each haptic cycle (`hapsim serve`): before the world steps, it
// restarts a device's tools when its input's source changed (a device host joined or went
// silent: the tools jump, and no proxy, velocity or stick point should survive that) and hands
// the world the other users' inputs; after the step, it builds each tool's local contact model
// (world/local_model_builder.h) and writes it on the session's LocalModel topic, answering the
// state of that tool's device host the step used. A rig that grasps a ball also has its gripper
// pads' models served (rig/pad_models.h), keyed after its master's tools, so the master feels the
// grasp. Allocation-free.
#pragma once

#include "hapsim/net/legacy_force_udp.h"
#include "hapsim/net/local_model_codec.h"
#include "hapsim/net/remote_device.h"
#include "hapsim/net/topic_writer.h"
#include "hapsim/rig/rig_description.h"
#include "hapsim/runtime/world_haptic_client.h"
#include "hapsim/world/local_model_builder.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

namespace hapsim::net {

/// The push each tool's device rendered, read back from the device's command the way a device
/// host fills it (net/device_host_client.cpp): a tool on finger f felt finger_force_n[f]; the
/// tools on no finger share force_world_n, so it is theirs when there is exactly one. NaN where
/// it cannot be told (a finger the command does not carry, several tip tools, non-finite).
/// `tool_finger[t]` is tool t's finger (-1: none); writes min(sizes) entries. haptic path
void rendered_push_per_tool(const DeviceCommand& rendered, std::span<const int> tool_finger,
                            std::span<double> push_n) noexcept;

class LocalModelPublisher final : public WorldCycleObserver {
 public:
  /// Models for the tools of `world`: `devices[k]` is world device k's link (ToolDescription::
  /// device; one per named device host, or the one device of a one-user scene). Device k's models
  /// are keyed (first_device_id + k, the tool's index among k's tools); a device's tools beyond
  /// kMaxFingers get none. Device 0 is the session's step input; the others' inputs are read here
  /// each cycle (World::set_device_input). A world with a rig that grasps (grasps_ball) also
  /// gets its two pads' models, keyed (first_device_id, device 0's tool count + pad): the rig's
  /// master is device 0. The devices must outlive the publisher.
  LocalModelPublisher(const Participant& participant, const World& world,
                      std::span<RemoteDevice* const> devices, std::uint16_t first_device_id,
                      std::uint64_t scene_hash, LocalModelBuildOptions options = {});

  /// Also send every step's finger forces (the command after safety) as the knee paper's legacy
  /// packet, full scale `finger_max_n` (`serve --legacy-force-udp`). Not owned.
  void send_legacy_forces(LegacyForceUdpSender* sender, double finger_max_n) noexcept {
    legacy_ = sender;
    legacy_finger_max_n_ = finger_max_n;
  }

  /// haptic path
  void before_step(World& world) noexcept override;
  /// haptic path
  void after_step(const World& world, const HapticCycle& cycle) noexcept override;
  /// haptic path: the world is paused, so every tool's model is free space (the device's force
  /// blends to zero within its blend time instead of fading as a silent host's would).
  void after_paused_cycle(const World& world, const HapticCycle& cycle) noexcept override;

  // Any thread.
  [[nodiscard]] std::uint64_t published() const noexcept {
    return published_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t refused_writes() const noexcept {
    return refused_.load(std::memory_order_relaxed);
  }
  /// Largest force device `device`'s host said it rendered (tip force, or a finger's), N.
  [[nodiscard]] double peak_rendered_force_n(std::size_t device = 0) const noexcept {
    return device < peak_rendered_n_.size()
               ? peak_rendered_n_[device].load(std::memory_order_relaxed)
               : 0.0;
  }

 private:
  /// One world device: its link and its tools (world index, finger).
  struct DeviceTools {
    RemoteDevice* link = nullptr;
    std::vector<std::size_t> tools;  ///< world tool indices, at most kMaxFingers
    std::vector<int> finger;
    std::vector<double> push_n;  ///< scratch: what it rendered, per tool
  };

  TopicWriter<hapsim_msg_LocalModel> writer_;
  LocalModelBuilder builder_;
  std::uint16_t first_device_id_;
  std::uint64_t scene_hash_;
  std::vector<DeviceTools> devices_;
  std::vector<LocalContactModel> models_;  ///< per world tool
  std::vector<double> rendered_push_n_;    ///< per world tool, for World::set_rendered_push
  /// The world's rig when it grasps a ball (and its master has room for two more keys), else
  /// null; its pads' models this step.
  const TeleopRigDescription* grasp_rig_ = nullptr;
  std::array<LocalContactModel, 2> pad_models_{};
  double validity_radius_m_ = 0.0;
  /// Sets each keyed tool's device_sequence (the state of its host the step used, 0: none) and
  /// writes them. haptic path
  void write_models() noexcept;

  std::uint64_t sequence_ = 0;
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::array<std::atomic<double>, kMaxWorldDevices> peak_rendered_n_{};
  LegacyForceUdpSender* legacy_ = nullptr;
  double legacy_finger_max_n_ = 0.0;
};

}  // namespace hapsim::net
