#include "hapsim/net/remote_device.h"

#include "hapsim/core/error.h"
#include "hapsim/runtime/deadline_clock.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

namespace hapsim::net {

RemoteDevice::RemoteDevice(const Participant& participant, std::uint16_t device_id,
                           std::uint64_t scene_hash, Device& fallback, double host_timeout_s)
    : states_(participant),
      gate_(device_id, scene_hash),
      device_id_(device_id),
      fallback_(fallback),
      host_timeout_ns_(static_cast<std::int64_t>(host_timeout_s * 1e9)),
      host_seen_ns_(std::numeric_limits<std::int64_t>::min() / 2) {
  // A waitset on the state reader's data-available status, for the lockstep wait.
  waitset_ = check_dds(dds_create_waitset(participant.participant()), "creating a waitset");
  check_dds(dds_set_status_mask(states_.handle(), DDS_DATA_AVAILABLE_STATUS),
            "watching device states");
  check_dds(dds_waitset_attach(waitset_, states_.handle(), 0), "watching device states");
}

RemoteDevice::~RemoteDevice() {
  (void)dds_delete(waitset_);
}

void RemoteDevice::set_link_shim(const LinkShimOptions& options) {
  link_ = std::make_unique<LinkShim<hapsim_msg_DeviceState, kLinkCapacity>>(options);
  link_epoch_ns_ = monotonic_ns();
}

// haptic path
bool RemoteDevice::admit_state(const hapsim_msg_DeviceState& m, std::int64_t now_ns,
                               dds_instance_handle_t writer) noexcept {
  if (std::find(sibling_ids_.begin(),
                sibling_ids_.begin() + static_cast<std::ptrdiff_t>(sibling_count_), m.device_id) !=
      sibling_ids_.begin() + static_cast<std::ptrdiff_t>(sibling_count_)) {
    return false;  // another user's state in this world: its own link counts it
  }
  // One host per device: a second one on this id (a name already taken) steers nothing while
  // the first drives; it is told by the models, which answer the first host's states only.
  if (writer != 0 && followed_writer_ != 0 && writer != followed_writer_ &&
      m.device_id == device_id_ && now_ns - host_seen_ns_ < host_timeout_ns_) {
    verdicts_[static_cast<std::size_t>(SampleVerdict::kOtherHost)].fetch_add(
        1, std::memory_order_relaxed);
    other_host_states_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  const SampleVerdict verdict = gate_.admit(m, host_state_);
  verdicts_[static_cast<std::size_t>(verdict)].fetch_add(1, std::memory_order_relaxed);
  if (verdict == SampleVerdict::kAccepted) {
    host_seen_ns_ = now_ns;
    if (writer != 0) {
      followed_writer_ = writer;
    }
    return true;
  }
  return false;
}

// haptic path
bool RemoteDevice::take_states(std::int64_t now_ns) noexcept {
  bool accepted = false;
  if (!link_) {
    states_.take([&](const hapsim_msg_DeviceState& m, const dds_sample_info_t& info) {
      accepted = admit_state(m, now_ns, info.publication_handle) || accepted;
    });
    return accepted;
  }
  const double link_s = static_cast<double>(now_ns - link_epoch_ns_) * 1e-9;
  states_.take([&](const hapsim_msg_DeviceState& m, const dds_sample_info_t&) {
    link_lost_.fetch_add(link_->send(m, link_s) ? 0 : 1, std::memory_order_relaxed);
  });
  (void)link_->deliver(link_s, [&](const hapsim_msg_DeviceState& m) {
    accepted = admit_state(m, now_ns, 0) || accepted;
  });
  return accepted;
}

// haptic path
DeviceInput RemoteDevice::read(double time_s) noexcept {
  std::int64_t now_ns = monotonic_ns();
  bool fresh = take_states(now_ns);
  if (lockstep_wait_ns_ > 0 && driving_.load(std::memory_order_relaxed)) {
    // Step on the host's *next* state, not on one that has waited here since: the model then
    // leaves as soon as the state arrived, and the loop's phase follows the device's.
    lockstep_waits_.fetch_add(1, std::memory_order_relaxed);
    const bool arrived = dds_waitset_wait(waitset_, nullptr, 0, lockstep_wait_ns_) > 0;
    now_ns = monotonic_ns();
    if (arrived && take_states(now_ns)) {
      fresh = true;
    } else {
      lockstep_timeouts_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  const bool driving = now_ns - host_seen_ns_ < host_timeout_ns_;
  if (driving != driving_.load(std::memory_order_relaxed)) {
    driving_.store(driving, std::memory_order_relaxed);
    transitions_.fetch_add(1, std::memory_order_relaxed);
    switched_ = true;
    if (!driving) {
      // A host that comes back (or a restarted one) numbers its states afresh.
      gate_.forget_order();
    }
    has_rates_from_ = false;  // nor are the old host's joints a rate's start
  }
  // The fallback is read every cycle, so a script keeps its own time while a host drives.
  DeviceInput input = fallback_.read(time_s);
  const double dt_s = std::clamp(time_s - previous_time_s_, 0.0, 0.01);
  previous_time_s_ = time_s;
  if (driving) {
    input = host_state_.input;
    // The input keeps the host's own clock, shifted to read as this loop's time when the host
    // joined: after a stall (here or there) one step may take several of the host's periods of
    // motion, and the world differences the tool's velocity over the input's time, not over its
    // step (stage::input_motion_time_s). Only differences of the host's clock are used.
    // Anchored afresh when a host joins or its clock went back (a host restarted within the
    // timeout numbers its time from zero again).
    if (switched_ || !std::isfinite(host_time_offset_s_) ||
        host_state_.input.time_s < host_time_last_s_) {
      host_time_offset_s_ = time_s - host_state_.input.time_s;
    }
    host_time_last_s_ = host_state_.input.time_s;
    // A cycle without a new state (late, lost) moves the device on at its reported velocity
    // instead of holding it: held, then caught up, it would jump two cycles at once, and the
    // world's velocity (and damping force) with it. A few cycles at most, then it holds.
    if (fresh) {
      note_rates(host_state_.input);
    }
    const bool after_reckoning = fresh && missed_states_ > 0;
    missed_states_ = fresh ? 0 : std::min(missed_states_ + 1, kMaxDeadReckoned);
    const double reckoned_s = dt_s * missed_states_;
    input.time_s = host_state_.input.time_s + host_time_offset_s_ + reckoned_s;
    if (missed_states_ > 0 && host_state_.v_world_m_per_s.allFinite()) {
      input.p_world += host_state_.v_world_m_per_s * reckoned_s;
    }
    // A master arm's joints too: held, the served slave would stand a cycle and then jump two,
    // and the ball its pads hold would take that step's acceleration (a 0.2 m/s carry stopping
    // and restarting within 1 ms is 20 N on a 100 g ball).
    if (missed_states_ > 0) {
      for (int j = 0; j < std::min(input.joint_count, kMaxDeviceJoints); ++j) {
        const auto k = static_cast<std::size_t>(j);
        input.joint_rad[k] += joint_rate_rad_per_s_[k] * reckoned_s;
      }
      for (int f = 0; f < std::min(input.finger_count, kMaxFingers); ++f) {
        const auto k = static_cast<std::size_t>(f);
        input.finger_rad[k] += finger_rate_rad_per_s_[k] * reckoned_s;
      }
    }
    // The first real state after reckoned ones corrects the estimate: that correction is not
    // motion the device made in the little host time since the estimate's stamp (a state late
    // by 0.1 ms is stamped 0.1 ms after it, and 0.05 mm over 0.1 ms reads as 0.5 m/s, a damping
    // force of its own). It takes at least a step; later stamps keep their differences.
    if (after_reckoning && input.time_s < previous_input_time_s_ + dt_s) {
      host_time_offset_s_ += previous_input_time_s_ + dt_s - input.time_s;
      input.time_s = previous_input_time_s_ + dt_s;
    }
    previous_input_time_s_ = input.time_s;
    cycles_driven_.fetch_add(1, std::memory_order_relaxed);
  }
  return input;
}

// haptic path
void RemoteDevice::note_rates(const DeviceInput& newest) noexcept {
  // Differenced over the host's own clock; a gap longer than a few cycles is no rate.
  const double dt_s = newest.time_s - rates_from_.time_s;
  const bool usable = has_rates_from_ && dt_s > 0.0 && dt_s <= 0.05 &&
                      newest.joint_count == rates_from_.joint_count &&
                      newest.finger_count == rates_from_.finger_count;
  const auto rate = [&](double now, double before) {
    const double r = usable ? (now - before) / dt_s : 0.0;
    return std::isfinite(r) ? r : 0.0;
  };
  for (std::size_t j = 0; j < joint_rate_rad_per_s_.size(); ++j) {
    joint_rate_rad_per_s_[j] = rate(newest.joint_rad[j], rates_from_.joint_rad[j]);
  }
  for (std::size_t f = 0; f < finger_rate_rad_per_s_.size(); ++f) {
    finger_rate_rad_per_s_[f] = rate(newest.finger_rad[f], rates_from_.finger_rad[f]);
  }
  rates_from_ = newest;
  has_rates_from_ = true;
}

bool RemoteDevice::wait_for_host(double timeout_s, const std::atomic<bool>* stop) {
  const std::int64_t give_up_ns = monotonic_ns() + static_cast<std::int64_t>(timeout_s * 1e9);
  for (;;) {
    const std::int64_t now_ns = monotonic_ns();
    take_states(now_ns);
    if (host_seen_ns_ == now_ns) {
      return true;
    }
    if (now_ns > give_up_ns || (stop != nullptr && stop->load(std::memory_order_relaxed))) {
      return false;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

VerdictCounts RemoteDevice::verdicts() const noexcept {
  VerdictCounts counts{};
  for (std::size_t v = 0; v < kSampleVerdicts; ++v) {
    counts[v] = verdicts_[v].load(std::memory_order_relaxed);
  }
  return counts;
}

}  // namespace hapsim::net
