#include "hapsim/net/model_publisher.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapsim::net {

LocalModelPublisher::LocalModelPublisher(const Participant& participant, const World& world,
                                         RemoteDevice& device, std::uint16_t device_id,
                                         std::uint64_t scene_hash, std::size_t tools,
                                         LocalModelBuildOptions options)
    : writer_(participant),
      builder_(world.model(), options),
      device_(device),
      device_id_(device_id),
      scene_hash_(scene_hash),
      models_(std::min<std::size_t>(tools, kMaxFingers)) {
  for (const ToolDescription& tool : world.description().tools) {
    tool_finger_.push_back(tool.finger);
  }
  rendered_push_n_.assign(tool_finger_.size(), std::numeric_limits<double>::quiet_NaN());
}

// haptic path
void rendered_push_per_tool(const DeviceCommand& rendered, std::span<const int> tool_finger,
                            std::span<double> push_n) noexcept {
  const std::size_t n = std::min(tool_finger.size(), push_n.size());
  const auto tip_tools = static_cast<std::size_t>(
      std::count_if(tool_finger.begin(), tool_finger.begin() + static_cast<std::ptrdiff_t>(n),
                    [](int finger) { return finger < 0; }));
  for (std::size_t t = 0; t < n; ++t) {
    const int finger = tool_finger[t];
    double push = std::numeric_limits<double>::quiet_NaN();
    if (finger >= 0 && finger < std::min(rendered.finger_count, kMaxFingers)) {
      push = rendered.finger_force_n[static_cast<std::size_t>(finger)];
    } else if (finger < 0 && tip_tools == 1 && rendered.force_world_n.allFinite()) {
      push = rendered.force_world_n.norm();
    }
    push_n[t] =
        std::isfinite(push) && push >= 0.0 ? push : std::numeric_limits<double>::quiet_NaN();
  }
}

// haptic path
void LocalModelPublisher::before_step(World& world) noexcept {
  if (device_.take_source_switch()) {
    world.restart_tools();  // a 1 m teleport: never drag the proxies across the body
  }
  // SPEC §8: the tissue gives way to what the device host rendered, while it drives the tools.
  if (device_.host_driving()) {
    rendered_push_per_tool(device_.host_state().rendered, tool_finger_, rendered_push_n_);
    world.set_rendered_push(rendered_push_n_);
  }
}

// haptic path
void LocalModelPublisher::after_step(const World& world, const HapticCycle& cycle) noexcept {
  if (legacy_ != nullptr && cycle.output != nullptr) {
    (void)legacy_->send_command(*cycle.output, legacy_finger_max_n_);  // failures are counted
  }
  const bool driving = device_.host_driving();
  builder_.build(world.state(), ++sequence_, driving ? device_.host_state().sequence : 0, models_);
  write_models();
  if (driving) {
    const DeviceCommand& rendered = device_.host_state().rendered;
    double peak = rendered.force_world_n.allFinite() ? rendered.force_world_n.norm() : 0.0;
    for (int f = 0; f < std::min(rendered.finger_count, kMaxFingers); ++f) {
      const double finger_n = rendered.finger_force_n[static_cast<std::size_t>(f)];
      peak = std::isfinite(finger_n) ? std::max(peak, finger_n) : peak;
    }
    if (peak > peak_rendered_n_.load(std::memory_order_relaxed)) {
      peak_rendered_n_.store(peak, std::memory_order_relaxed);
    }
  }
}

// haptic path
void LocalModelPublisher::after_paused_cycle(const World& world,
                                             const HapticCycle& /*cycle*/) noexcept {
  ++sequence_;
  const std::uint64_t answered = device_.host_driving() ? device_.host_state().sequence : 0;
  for (LocalContactModel& m : models_) {
    m = LocalContactModel{};  // invalid: free space
    m.sequence = sequence_;
    m.device_sequence = answered;
    m.sim_time_s = world.state().time_s;
  }
  write_models();
}

// haptic path
void LocalModelPublisher::write_models() noexcept {
  std::uint64_t written = 0;
  for (std::size_t t = 0; t < models_.size(); ++t) {
    written += writer_.write(encode_local_model(
                   models_[t], {device_id_, static_cast<std::uint16_t>(t)}, scene_hash_))
                   ? 1
                   : 0;
  }
  published_.fetch_add(written, std::memory_order_relaxed);
  refused_.fetch_add(models_.size() - written, std::memory_order_relaxed);
}

}  // namespace hapsim::net
