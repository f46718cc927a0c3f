#include "hapsim/net/model_publisher.h"

#include "hapsim/rig/pad_models.h"
#include "hapsim/rig/rig_controller.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapsim::net {

LocalModelPublisher::LocalModelPublisher(const Participant& participant, const World& world,
                                         std::span<RemoteDevice* const> devices,
                                         std::uint16_t first_device_id, std::uint64_t scene_hash,
                                         LocalModelBuildOptions options)
    : writer_(participant),
      builder_(world.model(), options),
      first_device_id_(first_device_id),
      scene_hash_(scene_hash),
      devices_(std::min<std::size_t>(devices.size(), kMaxWorldDevices)) {
  for (std::size_t k = 0; k < devices_.size(); ++k) {
    devices_[k].link = devices[k];
  }
  const std::vector<ToolDescription>& tools = world.description().tools;
  for (std::size_t t = 0; t < tools.size(); ++t) {
    const auto k = static_cast<std::size_t>(tools[t].device);
    if (k < devices_.size() && devices_[k].tools.size() < static_cast<std::size_t>(kMaxFingers)) {
      devices_[k].tools.push_back(t);
      devices_[k].finger.push_back(tools[t].finger);
    }
  }
  for (DeviceTools& d : devices_) {
    d.push_n.assign(d.tools.size(), std::numeric_limits<double>::quiet_NaN());
  }
  models_.resize(tools.size());
  rendered_push_n_.assign(tools.size(), std::numeric_limits<double>::quiet_NaN());
  const TeleopRigDescription* rig = rig_description(world.description());
  if (rig != nullptr && grasps_ball(*rig) && !devices_.empty() &&
      devices_[0].tools.size() + 2 <= static_cast<std::size_t>(kMaxFingers)) {
    grasp_rig_ = rig;
  }
  validity_radius_m_ = options.validity_radius_m;
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
  bool any_driving = false;
  for (std::size_t k = 0; k < devices_.size(); ++k) {
    RemoteDevice& link = *devices_[k].link;
    if (k > 0) {
      // Device 0 is the step's own input (the session reads it); the others' are read here.
      world.set_device_input(static_cast<int>(k), link.read(world.state().time_s));
    }
    if (link.take_source_switch()) {
      // A 1 m teleport: never drag the proxies across the body. One user: every tool.
      if (devices_.size() == 1) {
        world.restart_tools();
      } else {
        world.restart_tools(static_cast<int>(k));
      }
    }
    any_driving = any_driving || link.host_driving();
  }
  // SPEC §8: the tissue gives way to what each device host rendered, while it drives its tools.
  if (any_driving) {
    for (DeviceTools& d : devices_) {
      if (d.link->host_driving()) {
        rendered_push_per_tool(d.link->host_state().rendered, d.finger, d.push_n);
      } else {
        std::fill(d.push_n.begin(), d.push_n.end(), std::numeric_limits<double>::quiet_NaN());
      }
      for (std::size_t i = 0; i < d.tools.size(); ++i) {
        rendered_push_n_[d.tools[i]] = d.push_n[i];
      }
    }
    world.set_rendered_push(rendered_push_n_);
  }
}

// haptic path
void LocalModelPublisher::after_step(const World& world, const HapticCycle& cycle) noexcept {
  if (legacy_ != nullptr && cycle.output != nullptr) {
    (void)legacy_->send_command(*cycle.output, legacy_finger_max_n_);  // failures are counted
  }
  builder_.build(world.state(), ++sequence_, 0, models_);
  if (grasp_rig_ != nullptr) {
    build_pad_models(*grasp_rig_, world.state(), sequence_, validity_radius_m_, pad_models_);
  }
  write_models();
  for (std::size_t k = 0; k < devices_.size(); ++k) {
    const RemoteDevice& link = *devices_[k].link;
    if (!link.host_driving()) {
      continue;
    }
    const DeviceCommand& rendered = link.host_state().rendered;
    double peak = rendered.force_world_n.allFinite() ? rendered.force_world_n.norm() : 0.0;
    for (int f = 0; f < std::min(rendered.finger_count, kMaxFingers); ++f) {
      const double finger_n = rendered.finger_force_n[static_cast<std::size_t>(f)];
      peak = std::isfinite(finger_n) ? std::max(peak, finger_n) : peak;
    }
    if (peak > peak_rendered_n_[k].load(std::memory_order_relaxed)) {
      peak_rendered_n_[k].store(peak, std::memory_order_relaxed);
    }
  }
}

// haptic path
void LocalModelPublisher::after_paused_cycle(const World& world,
                                             const HapticCycle& /*cycle*/) noexcept {
  ++sequence_;
  for (LocalContactModel& m : models_) {
    m = LocalContactModel{};  // invalid: free space
    m.sequence = sequence_;
    m.sim_time_s = world.state().time_s;
  }
  for (LocalContactModel& m : pad_models_) {
    m = LocalContactModel{};
    m.sequence = sequence_;
    m.sim_time_s = world.state().time_s;
  }
  write_models();
}

// haptic path
void LocalModelPublisher::write_models() noexcept {
  std::uint64_t written = 0;
  std::uint64_t refused = 0;
  for (std::size_t k = 0; k < devices_.size(); ++k) {
    const DeviceTools& d = devices_[k];
    const std::uint64_t answered = d.link->host_driving() ? d.link->host_state().sequence : 0;
    const auto device_id = static_cast<std::uint16_t>(first_device_id_ + k);
    const auto write = [&](LocalContactModel& m, std::size_t key) {
      m.device_sequence = answered;
      const bool ok = writer_.write(
          encode_local_model(m, {device_id, static_cast<std::uint16_t>(key)}, scene_hash_));
      written += ok ? 1 : 0;
      refused += ok ? 0 : 1;
    };
    for (std::size_t i = 0; i < d.tools.size(); ++i) {
      write(models_[d.tools[i]], i);
    }
    if (k == 0 && grasp_rig_ != nullptr) {
      for (std::size_t i = 0; i < pad_models_.size(); ++i) {
        write(pad_models_[i], d.tools.size() + i);  // the rig's master: its pads after its tools
      }
    }
  }
  published_.fetch_add(written, std::memory_order_relaxed);
  refused_.fetch_add(refused, std::memory_order_relaxed);
}

}  // namespace hapsim::net
