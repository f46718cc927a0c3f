// The device a simulation host steps its world with (`hapsim serve`): the newest gated state of
// a device host (`hapsim device`, or anything that writes the DeviceState topic) while its states
// keep coming, else a fallback device (the scene's own script). Every received state goes
// through the DeviceStateGate; rejections are counted by reason. Whether a host drives is decided
// by this process's own clock (a state is fresh for `host_timeout_s` after it arrived): clocks are
// never compared across hosts.
#pragma once

#include "hapsim/device/device.h"
#include "hapsim/net/device_state_gate.h"
#include "hapsim/net/link_shim.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/topic_reader.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>

namespace hapsim::net {

class RemoteDevice final : public Device {
 public:
  /// `fallback` must outlive this device; its profile is this device's.
  RemoteDevice(const Participant& participant, std::uint16_t device_id, std::uint64_t scene_hash,
               Device& fallback, double host_timeout_s = 0.1);
  ~RemoteDevice() override;
  RemoteDevice(const RemoteDevice&) = delete;
  RemoteDevice& operator=(const RemoteDevice&) = delete;
  RemoteDevice(RemoteDevice&&) = delete;
  RemoteDevice& operator=(RemoteDevice&&) = delete;

  /// `--link-shim`: received states go through a simulated link first (its clock: seconds since
  /// this call). Before the loop starts.
  void set_link_shim(const LinkShimOptions& options);
  [[nodiscard]] std::uint64_t link_lost() const noexcept {
    return link_lost_.load(std::memory_order_relaxed);
  }

  /// Several users: the device ids of the other users' hosts in this world. Their states are
  /// theirs, not strangers': skipped without a verdict (not counted as "other device"). Before
  /// the loop starts; at most kMaxSiblings.
  void set_sibling_device_ids(std::span<const std::uint16_t> ids) noexcept {
    sibling_count_ = std::min(ids.size(), sibling_ids_.size());
    std::copy_n(ids.begin(), sibling_count_, sibling_ids_.begin());
  }

  /// Lockstep with the device host: while one drives and no new state came this cycle, read()
  /// waits up to `wait_s` for the next one (on a waitset: no spinning), so the step answers a
  /// state as soon as it arrives instead of at the next deadline — the model then reaches the
  /// device before its next cycle. 0 (the default): never wait. Before the loop starts.
  void set_lockstep_wait(double wait_s) noexcept {
    lockstep_wait_ns_ = static_cast<std::int64_t>(wait_s * 1e9);
  }

  /// haptic path: takes the states that arrived, then the host's newest input (stamped
  /// `time_s`) while it drives, else the fallback's.
  [[nodiscard]] DeviceInput read(double time_s) noexcept override;
  /// Forwarded to the fallback (a script ignores it); the host renders from its local models.
  void write(const DeviceCommand& command) noexcept override { fallback_.write(command); }
  [[nodiscard]] const DeviceProfile& profile() const noexcept override {
    return fallback_.profile();
  }
  [[nodiscard]] DeviceStatus status() const noexcept override { return {}; }

  /// Before the loop starts (the calling thread owns the reader then): takes states until one is
  /// accepted or `timeout_s` passes; true when a host is there.
  bool wait_for_host(double timeout_s, const std::atomic<bool>* stop = nullptr);

  /// haptic path: true once after the input's source changed (host joined or went silent): the
  /// tools jump, so the world should restart them (World::restart_tools).
  bool take_source_switch() noexcept {
    const bool switched = switched_;
    switched_ = false;
    return switched;
  }
  /// haptic path: the newest accepted host state (what the device rendered is in it).
  [[nodiscard]] const DeviceStateSample& host_state() const noexcept { return host_state_; }

  // Any thread.
  [[nodiscard]] bool host_driving() const noexcept {
    return driving_.load(std::memory_order_relaxed);
  }
  /// Host joins plus silences so far (a monitor prints each one).
  [[nodiscard]] std::uint64_t transitions() const noexcept {
    return transitions_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t cycles_driven() const noexcept {
    return cycles_driven_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] VerdictCounts verdicts() const noexcept;
  /// States for this device from a second writer while the first one drives (another device
  /// host claiming the same device id, i.e. the same name): refused (kOtherHost).
  [[nodiscard]] std::uint64_t other_host_states() const noexcept {
    return other_host_states_.load(std::memory_order_relaxed);
  }
  /// Cycles that waited for the host's state, and those the wait ran out.
  [[nodiscard]] std::uint64_t lockstep_waits() const noexcept {
    return lockstep_waits_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t lockstep_timeouts() const noexcept {
    return lockstep_timeouts_.load(std::memory_order_relaxed);
  }

 private:
  /// True when a state was accepted.
  bool take_states(std::int64_t now_ns) noexcept;
  /// `writer`: the DDS writer it came from (0: not known, as through the link shim).
  bool admit_state(const hapsim_msg_DeviceState& m, std::int64_t now_ns,
                   dds_instance_handle_t writer) noexcept;

  TopicReader<hapsim_msg_DeviceState> states_;
  DeviceStateGate gate_;
  std::uint16_t device_id_;
  static constexpr std::size_t kMaxSiblings = 8;
  std::array<std::uint16_t, kMaxSiblings> sibling_ids_{};
  std::size_t sibling_count_ = 0;
  /// The device host followed: the writer of the first state accepted, until it is silent for
  /// the host timeout; another writer's states for this device meanwhile are refused.
  dds_instance_handle_t followed_writer_ = 0;
  std::atomic<std::uint64_t> other_host_states_{0};
  Device& fallback_;
  std::int64_t host_timeout_ns_;
  std::int64_t lockstep_wait_ns_ = 0;
  static constexpr std::size_t kLinkCapacity = 512;  ///< 500 ms of states
  std::unique_ptr<LinkShim<hapsim_msg_DeviceState, kLinkCapacity>> link_;
  std::int64_t link_epoch_ns_ = 0;
  std::atomic<std::uint64_t> link_lost_{0};
  /// The host's joint and finger rates between its two newest states (rad/s): a master arm's or
  /// a glove's reading moves on at them in a cycle without a new state, as the tip moves on at
  /// its velocity. haptic path
  void note_rates(const DeviceInput& newest) noexcept;
  std::array<double, kMaxDeviceJoints> joint_rate_rad_per_s_{};
  std::array<double, kMaxFingers> finger_rate_rad_per_s_{};
  DeviceInput rates_from_;  ///< the state the rates were differenced from
  bool has_rates_from_ = false;
  /// Cycles in a row without a new host state, dead-reckoned up to kMaxDeadReckoned.
  static constexpr int kMaxDeadReckoned = 3;
  int missed_states_ = 0;
  double previous_time_s_ = 0.0;
  /// This loop's time less the host's, when the host joined (its states' time on this clock).
  double host_time_offset_s_ = std::numeric_limits<double>::quiet_NaN();
  double host_time_last_s_ = 0.0;       ///< the newest host state's own time
  double previous_input_time_s_ = 0.0;  ///< the host input's time read() gave last
  dds_entity_t waitset_ = 0;
  DeviceStateSample host_state_;
  std::int64_t host_seen_ns_;
  bool switched_ = false;
  std::atomic<bool> driving_{false};
  std::atomic<std::uint64_t> transitions_{0};
  std::atomic<std::uint64_t> cycles_driven_{0};
  std::array<std::atomic<std::uint64_t>, kSampleVerdicts> verdicts_{};
  std::atomic<std::uint64_t> lockstep_waits_{0};
  std::atomic<std::uint64_t> lockstep_timeouts_{0};
};

}  // namespace hapsim::net
