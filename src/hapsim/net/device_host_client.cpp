#include "hapsim/net/device_host_client.h"

#include "hapsim/core/error.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/runtime/deadline_clock.h"

#include <algorithm>
#include <cmath>

namespace hapsim::net {

namespace {

// Tool count in the low byte, then a nibble per tool: its finger + 1 (0: the tip).
std::uint64_t pack_layout(const ServedScene& scene) noexcept {
  std::uint64_t packed = std::min<std::uint64_t>(scene.tool_count, kMaxFingers);
  for (std::size_t t = 0; t < kMaxFingers; ++t) {
    const auto nibble =
        static_cast<std::uint64_t>(std::clamp<int>(scene.tool_finger[t] + 1, 0, 15));
    packed |= nibble << (8 + 4 * t);
  }
  return packed;
}

void unpack_layout(std::uint64_t packed, ServedScene& scene) noexcept {
  scene.tool_count = static_cast<std::uint16_t>(packed & 0xffu);
  for (std::size_t t = 0; t < kMaxFingers; ++t) {
    scene.tool_finger[t] = static_cast<std::int16_t>(((packed >> (8 + 4 * t)) & 0xfu)) - 1;
  }
}

void raise_to(std::atomic<double>& peak, double value) noexcept {
  if (value > peak.load(std::memory_order_relaxed)) {
    peak.store(value, std::memory_order_relaxed);
  }
}

PassivityObserverOptions passivity_options(const DeviceHostOptions& options) {
  PassivityObserverOptions o = options.passivity;
  o.enabled = o.enabled && options.mode == ForceMode::kLocalModel;
  return o;
}

}  // namespace

LocalModelRenderOptions finger_render_options(const DeviceHostOptions& options) noexcept {
  LocalModelRenderOptions o = options.render;
  if (options.max_finger_force_n > 0.0) {
    o.max_force_n = options.max_finger_force_n;
  }
  return o;
}

DeviceHostClient::DeviceHostClient(const Participant& participant, const DeviceHostOptions& options)
    : options_(options),
      models_in_(participant),
      states_out_(participant),
      gate_(options.device_id, 0, 1, options.limits),
      renderers_{LocalModelRenderer(options.render), LocalModelRenderer(options.render),
                 LocalModelRenderer(options.render), LocalModelRenderer(options.render),
                 LocalModelRenderer(options.render)},
      passivity_{PassivityObserver(passivity_options(options)),
                 PassivityObserver(passivity_options(options)),
                 PassivityObserver(passivity_options(options)),
                 PassivityObserver(passivity_options(options)),
                 PassivityObserver(passivity_options(options))} {
  if (!(std::isfinite(options.max_force_rate_n_per_s) && options.max_force_rate_n_per_s > 0.0)) {
    throw Error("device host", "the force rate limit must be finite and > 0 N/s");
  }
  if (!(std::isfinite(options.max_finger_force_n) && options.max_finger_force_n >= 0.0)) {
    throw Error("device host", "the finger force rating must be finite and >= 0 N");
  }
  if (options.max_finger_force_n > 0.0) {
    (void)LocalModelRenderer(finger_render_options(options));  // checked here, not in the loop
  }
  if (options.link) {
    link_ = std::make_unique<LinkShim<hapsim_msg_LocalModel, kLinkCapacity>>(*options.link);
    link_epoch_s_ = static_cast<double>(monotonic_ns()) * 1e-9;
  }
  // Drawn below 2^62, so the numbering never wraps in a session; two hosts land within a
  // session's states of each other with odds of about 1e-9 a day.
  sequence_base_ =
      options.state_sequence_base != 0 ? options.state_sequence_base : (draw_serve_id() >> 2U) + 1;
  sequence_ = sequence_base_;
  rig_grasps_ = options.rig && grasps_ball(options.rig->description());
}

void DeviceHostClient::set_scene(const ServedScene& scene) noexcept {
  pending_hash_.store(scene.scene_hash, std::memory_order_relaxed);
  pending_serve_id_.store(scene.serve_id, std::memory_order_relaxed);
  pending_layout_.store(pack_layout(scene), std::memory_order_relaxed);
  pending_version_.fetch_add(1, std::memory_order_release);
}

// haptic path
void DeviceHostClient::apply_scene() noexcept {
  const std::uint64_t version = pending_version_.load(std::memory_order_acquire);
  if (version == applied_version_) {
    return;
  }
  applied_version_ = version;
  scene_.scene_hash = pending_hash_.load(std::memory_order_relaxed);
  scene_.serve_id = pending_serve_id_.load(std::memory_order_relaxed);
  unpack_layout(pending_layout_.load(std::memory_order_relaxed), scene_);
  // A new simulation numbers its models from 1 again and knows nothing of the old one's: start
  // from no model (the renderers blend the first one in from zero).
  // A grasping rig's pads are keyed after the master's tools.
  const int keys = std::min<int>(scene_.tool_count + (rig_grasps_ ? 2 : 0), kMaxFingers);
  gate_ = LocalModelGate(options_.device_id, scene_.scene_hash, std::max<int>(1, keys),
                         options_.limits);
  // A tool on a finger renders to the finger actuator's rating, the others to the tip's.
  for (std::size_t t = 0; t < renderers_.size(); ++t) {
    const bool on_finger = t < scene_.tool_count && scene_.tool_finger[t] >= 0;
    renderers_[t] = LocalModelRenderer(on_finger ? finger_render_options(options_)
                                                 : options_.render);  // checked: no throw
  }
  for (PassivityObserver& p : passivity_) {
    p.reset();
  }
  raw_models_ = {};
  followed_writer_ = 0;  // whoever serves the new scene
  scene_changes_.fetch_add(1, std::memory_order_relaxed);
}

// haptic path
void DeviceHostClient::take_models(double now_s, std::int64_t now_ns) noexcept {
  if (!link_) {
    models_in_.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t& info) {
      admit_model(m, now_s, now_ns, info.publication_handle);
    });
    return;
  }
  // Through the simulated link first: what arrived goes on it, what is due comes off it.
  const double link_s = now_s - link_epoch_s_;
  models_in_.take([&](const hapsim_msg_LocalModel& m, const dds_sample_info_t&) {
    link_lost_.fetch_add(link_->send(m, link_s) ? 0 : 1, std::memory_order_relaxed);
  });
  const std::size_t delivered = link_->deliver(
      link_s, [&](const hapsim_msg_LocalModel& m) { admit_model(m, now_s, now_ns, 0); });
  link_delivered_.fetch_add(delivered, std::memory_order_relaxed);
}

// haptic path
void DeviceHostClient::admit_model(const hapsim_msg_LocalModel& m, double now_s,
                                   std::int64_t now_ns, dds_instance_handle_t writer) noexcept {
  // The followed host answers until it has been silent as long as a model takes to fade out.
  const LocalModelRenderOptions& render = options_.render;
  const auto silent_ns =
      static_cast<std::int64_t>((render.stale_after_s + render.fade_time_s) * 1e9);
  if (writer != 0 && followed_writer_ != 0 && writer != followed_writer_ &&
      now_ns - followed_seen_ns_ < silent_ns) {
    verdicts_[static_cast<std::size_t>(SampleVerdict::kOtherHost)].fetch_add(
        1, std::memory_order_relaxed);
    return;
  }
  // A model for this device id that answers a state this host never sent: another device host
  // on the same id (the same name) sends states, and the simulation answers that host.
  if (m.device_id == options_.device_id && m.device_sequence != 0 &&
      (m.device_sequence <= sequence_base_ || m.device_sequence > sequence_)) {
    verdicts_[static_cast<std::size_t>(SampleVerdict::kOtherHost)].fetch_add(
        1, std::memory_order_relaxed);
    models_other_device_host_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  LocalContactModel model;
  const SampleVerdict verdict = gate_.admit(m, sequence_, model);
  verdicts_[static_cast<std::size_t>(verdict)].fetch_add(1, std::memory_order_relaxed);
  if (verdict != SampleVerdict::kAccepted) {
    return;
  }
  if (writer != 0) {
    followed_writer_ = writer;
    followed_seen_ns_ = now_ns;
  }
  if (model.device_sequence == 0) {
    models_not_ours_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  // The first model that answers a state closes its round trip.
  const std::size_t slot = model.device_sequence % kHistory;
  if (sequence_ - model.device_sequence < kHistory && !answered_[slot] &&
      state_sent_ns_[slot] > 0) {
    answered_[slot] = true;
    round_trip_us_.record_us(static_cast<double>(now_ns - state_sent_ns_[slot]) * 1e-3);
  }
  const auto tool = static_cast<std::size_t>(m.finger);
  if (options_.mode == ForceMode::kRaw) {
    raw_models_[tool] = model;
    raw_received_s_[tool] = now_s;
  } else {
    renderers_[tool].receive(model, now_s);
  }
  models_accepted_.fetch_add(1, std::memory_order_relaxed);
  last_model_ns_.store(now_ns, std::memory_order_relaxed);
  last_model_cycle_.store(sequence_, std::memory_order_relaxed);
  took_model_ = true;
}

// haptic path
Vec3 DeviceHostClient::key_force(std::size_t key, std::size_t point, double now_s) noexcept {
  if (options_.mode == ForceMode::kRaw) {
    const LocalModelRenderOptions& o = renderers_[key].options();
    const LocalContactModel& m = raw_models_[key];
    if (!m.valid) {
      return Vec3::Zero();
    }
    // The paper's raw force, held; still faded when stale and clamped (safety is not optional).
    const double age_s = now_s - raw_received_s_[key];
    const double fresh =
        age_s <= o.stale_after_s
            ? 1.0
            : std::clamp(1.0 - (age_s - o.stale_after_s) / std::max(o.fade_time_s, 1e-9), 0.0, 1.0);
    Vec3 f = m.f0_world_n * fresh;
    const double magnitude = f.norm();
    return magnitude > o.max_force_n ? Vec3(f * (o.max_force_n / magnitude)) : f;
  }
  LocalModelRenderer& renderer = renderers_[key];
  const LocalContactModel& m = renderer.newest();
  // Where the tool is now: where the simulation had it, moved as the device moved since.
  Vec3 x_tool_m = m.x0_world_m;
  if (m.valid && m.device_sequence > 0 && sequence_ - m.device_sequence < kHistory) {
    x_tool_m += p_m_[point] - p_history_m_[m.device_sequence % kHistory][point];
  }
  return renderer.render(x_tool_m, v_m_per_s_[point], now_s);
}

// haptic path
Vec3 DeviceHostClient::render_key(std::size_t key, std::size_t point, double dt_s, double now_s,
                                  bool& limited, std::uint64_t& acted,
                                  double& dissipated_j) noexcept {
  Vec3 f = key_force(key, point, now_s);
  PassivityObserver& observer = passivity_[key];
  if (f.isZero()) {
    observer.reset();  // free space: nothing stored, nothing owed
  }
  const std::uint64_t acted_before = observer.counts().acted;
  f = observer.filter(f, v_m_per_s_[point], dt_s);
  acted += observer.counts().acted - acted_before;
  dissipated_j += observer.counts().dissipated_j;
  const double max_step_n = options_.max_force_rate_n_per_s * dt_s;
  const Vec3 change = f - previous_force_n_[key];
  if (change.norm() > max_step_n) {
    f = previous_force_n_[key] + change * (max_step_n / change.norm());
    limited = true;
  }
  previous_force_n_[key] = f;
  return f;
}

// haptic path
const DeviceCommand& DeviceHostClient::step(const DeviceInput& input, double dt_s) {
  const std::int64_t now_ns = monotonic_ns();
  const double now_s = static_cast<double>(now_ns) * 1e-9;
  apply_scene();
  ++sequence_;
  // The points that move with the device: its own, or a rig master's carried tool on the slave's
  // target; a grasping rig's pads where that target and the master's grip put them.
  std::array<Vec3, kPoints> p_now{};
  p_now[0] = options_.rig
                 ? options_.rig->flange_point_target_world(input, options_.rig_tool_flange_m)
                 : input.p_world;
  if (rig_grasps_) {
    // The pads in the grip's frame, as their models are (rig/pad_models.h): relative to their
    // midpoint, so carrying the ball moves nothing and only the grip's opening squeezes it.
    const Vec3 pads[2] = {options_.rig->pad_centre_target_world(input, 0),
                          options_.rig->pad_centre_target_world(input, 1)};
    const Vec3 mid = 0.5 * (pads[0] + pads[1]);
    p_now[1] = pads[0] - mid;
    p_now[2] = pads[1] - mid;
  } else {
    p_now[1] = p_now[2] = p_now[0];
  }
  const bool has_previous = sequence_ > sequence_base_ + 1 && dt_s > 0.0;
  for (std::size_t j = 0; j < kPoints; ++j) {
    const Vec3 p = p_now[j].allFinite() ? p_now[j] : p_m_[j];
    v_m_per_s_[j] = has_previous ? Vec3((p - p_m_[j]) / dt_s) : Vec3::Zero();
    p_m_[j] = p;
    p_history_m_[sequence_ % kHistory][j] = p;
  }
  took_model_ = false;
  take_models(now_s, now_ns);

  command_ = DeviceCommand{};
  double largest_n = 0.0;
  bool limited = false;
  std::uint64_t acted = 0;
  double dissipated_j = 0.0;
  for (std::size_t t = 0; t < scene_.tool_count; ++t) {
    const Vec3 f = render_key(t, 0, dt_s, now_s, limited, acted, dissipated_j);
    largest_n = std::max(largest_n, f.norm());
    const int finger = scene_.tool_finger[t];
    if (finger >= 0 && finger < kMaxFingers) {
      double& finger_n = command_.finger_force_n[static_cast<std::size_t>(finger)];
      finger_n = std::max(finger_n, f.norm());
      command_.finger_count = std::max(command_.finger_count, finger + 1);
    } else {
      command_.force_world_n += f;
    }
  }
  if (options_.rig) {
    // The master feels the force at the slave's tool through its joints and the grasp through its
    // fingers, as the served rig's command makes them (rig_command.cpp): the carried tool's force
    // and the pads' (what the ball pushes on them), and the pads' mean push.
    rig_force_world_n_ = command_.force_world_n;
    Vec3 at_slave_tool_n = rig_force_world_n_;
    double grasp_n = 0.0;
    int pressing = 0;
    for (std::size_t i = 0; i < 2 && rig_grasps_; ++i) {
      const std::size_t key = scene_.tool_count + i;
      if (key >= static_cast<std::size_t>(kMaxFingers)) {
        break;
      }
      const Vec3 f = render_key(key, 1 + i, dt_s, now_s, limited, acted, dissipated_j);
      const LocalContactModel& m =
          options_.mode == ForceMode::kRaw ? raw_models_[key] : renderers_[key].newest();
      at_slave_tool_n += f;
      const double push_n = f.dot(m.normal_world);
      grasp_n += 0.5 * std::max(0.0, push_n);
      pressing += push_n > 0.0 ? 1 : 0;
    }
    if (pressing == 2) {
      ++held_cycles_;
      mean_held_force_n_ +=
          (at_slave_tool_n.norm() - mean_held_force_n_) / static_cast<double>(held_cycles_);
      published_mean_held_force_n_.store(mean_held_force_n_, std::memory_order_relaxed);
      published_held_cycles_.store(held_cycles_, std::memory_order_relaxed);
    }
    largest_n = at_slave_tool_n.norm();
    command_ = DeviceCommand{};
    options_.rig->master_command({input.joint_rad[0], input.joint_rad[1], input.joint_rad[2]},
                                 at_slave_tool_n, grasp_n, command_);
    double largest_torque_nm = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {  // the arm's: the fingers' are the grasp's
      largest_torque_nm = std::max(largest_torque_nm, std::abs(command_.joint_torque_nm[j]));
    }
    raise_to(peak_joint_torque_nm_, largest_torque_nm);  // one atomic a cycle, not one a joint
    raise_to(peak_grasp_force_n_, command_.finger_force_n[0]);
  }
  rate_limited_.fetch_add(limited ? 1 : 0, std::memory_order_relaxed);
  passivity_cycles_.fetch_add(acted > 0 ? 1 : 0, std::memory_order_relaxed);
  passivity_dissipated_j_.store(dissipated_j, std::memory_order_relaxed);
  force_n_.store(largest_n, std::memory_order_relaxed);
  if (took_model_) {
    force_at_last_model_n_.store(largest_n, std::memory_order_relaxed);
  }
  raise_to(peak_force_n_, largest_n);
  if (largest_n > 0.0) {
    last_force_ns_.store(now_ns, std::memory_order_relaxed);
    last_force_cycle_.store(sequence_, std::memory_order_relaxed);
  }
  cycles_.fetch_add(1, std::memory_order_relaxed);
  return command_;
}

// haptic path
void DeviceHostClient::after_cycle(const HapticCycle& cycle) noexcept {
  if (scene_.scene_hash == 0 || cycle.input == nullptr || cycle.output == nullptr) {
    return;  // no simulation host known yet: nobody to tell
  }
  state_.device_id = options_.device_id;
  state_.sequence = sequence_;
  state_.input = *cycle.input;
  state_.v_world_m_per_s = v_m_per_s_[0];
  state_.rendered = *cycle.output;
  if (options_.rig) {
    // A master renders joint torques: the push its tissue takes (SPEC §8) is the force at the
    // slave's tool they stand for, none while the safety layer holds the master at zero.
    const DeviceCommand& out = *cycle.output;
    bool torque = false;
    for (int i = 0; i < out.joint_count && i < kMaxDeviceJoints; ++i) {
      torque = torque || out.joint_torque_nm[static_cast<std::size_t>(i)] != 0.0;
    }
    state_.rendered.force_world_n = torque ? rig_force_world_n_ : Vec3::Zero();
  }
  const std::size_t slot = sequence_ % kHistory;
  state_sent_ns_[slot] = monotonic_ns();
  answered_[slot] = false;
  if (states_out_.write(encode_device_state(state_, scene_.scene_hash))) {
    states_published_.fetch_add(1, std::memory_order_relaxed);
  }
}

DeviceHostStatus DeviceHostClient::status() const noexcept {
  DeviceHostStatus s;
  s.cycles = cycles_.load(std::memory_order_relaxed);
  s.states_published = states_published_.load(std::memory_order_relaxed);
  s.models_accepted = models_accepted_.load(std::memory_order_relaxed);
  s.models_not_ours = models_not_ours_.load(std::memory_order_relaxed);
  s.models_other_device_host = models_other_device_host_.load(std::memory_order_relaxed);
  for (std::size_t v = 0; v < kSampleVerdicts; ++v) {
    s.verdicts[v] = verdicts_[v].load(std::memory_order_relaxed);
  }
  s.last_model_ns = last_model_ns_.load(std::memory_order_relaxed);
  s.last_force_ns = last_force_ns_.load(std::memory_order_relaxed);
  s.last_model_cycle = last_model_cycle_.load(std::memory_order_relaxed);
  s.last_force_cycle = last_force_cycle_.load(std::memory_order_relaxed);
  s.force_n = force_n_.load(std::memory_order_relaxed);
  s.force_at_last_model_n = force_at_last_model_n_.load(std::memory_order_relaxed);
  s.peak_force_n = peak_force_n_.load(std::memory_order_relaxed);
  s.peak_joint_torque_nm = peak_joint_torque_nm_.load(std::memory_order_relaxed);
  s.peak_grasp_force_n = peak_grasp_force_n_.load(std::memory_order_relaxed);
  s.mean_held_force_n = published_mean_held_force_n_.load(std::memory_order_relaxed);
  s.held_cycles = published_held_cycles_.load(std::memory_order_relaxed);
  s.rate_limited_cycles = rate_limited_.load(std::memory_order_relaxed);
  s.scene_changes = scene_changes_.load(std::memory_order_relaxed);
  s.round_trip_us = round_trip_us_.summary();
  s.link_lost = link_lost_.load(std::memory_order_relaxed);
  s.link_delivered = link_delivered_.load(std::memory_order_relaxed);
  s.passivity_cycles = passivity_cycles_.load(std::memory_order_relaxed);
  s.passivity_dissipated_j = passivity_dissipated_j_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace hapsim::net
