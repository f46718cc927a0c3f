#include "hapsim/device/legacy_glove_device.h"

#include "hapsim/core/error.h"

#include <cmath>
#include <utility>

namespace hapsim {

LegacyGloveDevice::LegacyGloveDevice(DeviceProfile profile,
                                     std::unique_ptr<LegacyPacketSource> source,
                                     LegacyGloveOptions options)
    : profile_(std::move(profile)), source_(std::move(source)), options_(options) {
  const std::string where = "legacy glove (profile '" + profile_.name + "')";
  if (profile_.finger_count < kLegacyForceFingers) {
    throw Error(where, "has " + std::to_string(profile_.finger_count) +
                           " force fingers; the legacy packet drives 4");
  }
  if (!(std::isfinite(profile_.max_finger_force_n) && profile_.max_finger_force_n > 0.0)) {
    throw Error(where, "max_finger_force_n must be finite and > 0 (the packet's full scale)");
  }
  if (!(options_.stale_after_s > 0.0 && options_.failed_after_s >= options_.stale_after_s)) {
    throw Error(where, "stale_after_s must be > 0 and failed_after_s >= stale_after_s");
  }
  if (options_.max_datagrams_per_read < 1) {
    throw Error(where, "max_datagrams_per_read must be at least 1");
  }
  const std::string stale = std::to_string(options_.stale_after_s);
  const std::string failed = std::to_string(options_.failed_after_s);
  stale_reason_ = "no valid legacy force packet for more than " + stale + " s";
  failed_reason_ = "no valid legacy force packet for more than " + failed + " s";
  waiting_reason_ = "no legacy force packet yet";
  never_reason_ = "no legacy force packet in " + failed + " s";
  reason_ = waiting_reason_;
  rendered_.finger_count = kLegacyForceFingers;
}

// haptic path
LegacyPacketVerdict LegacyGloveDevice::receive_datagram(std::span<const std::byte> datagram,
                                                        double now_s) noexcept {
  LegacyFingerForces forces{};
  const LegacyPacketVerdict verdict =
      decode_legacy_force(datagram, profile_.max_finger_force_n, forces);
  ++counts_[static_cast<std::size_t>(verdict)];
  // Datagrams are judged in arrival order: a later valid one replaces the newest. A datagram
  // stamped before the newest (a caller feeding old ones) cannot roll the glove back.
  if (verdict == LegacyPacketVerdict::kAccepted && std::isfinite(now_s) &&
      (!newest_s_ || now_s >= *newest_s_)) {
    newest_n_ = forces;
    newest_s_ = now_s;
  }
  return verdict;
}

// haptic path
DeviceInput LegacyGloveDevice::read(double time_s) noexcept {
  if (!first_read_s_) {
    first_read_s_ = time_s;
  }
  if (source_) {
    int drained = 0;
    while (true) {
      if (drained == options_.max_datagrams_per_read) {
        ++drain_capped_;
        break;
      }
      const std::optional<std::size_t> length = source_->receive(buffer_);
      if (!length) {
        break;
      }
      ++drained;
      // A datagram longer than the buffer shows as buffer-sized: one byte too long is long.
      const std::size_t seen = *length < buffer_.size() ? *length : buffer_.size();
      (void)receive_datagram(std::span<const std::byte>(buffer_.data(), seen), time_s);
    }
    counts_[static_cast<std::size_t>(LegacyPacketVerdict::kOtherSender)] = source_->other_senders();
  }

  // A NaN host time compares false everywhere: such a read is never fresh.
  const double age_s = newest_s_ ? time_s - *newest_s_ : time_s - *first_read_s_;
  if (!newest_s_) {
    const bool given_up = !(age_s <= options_.failed_after_s);
    health_ = given_up ? DeviceHealth::kFailed : DeviceHealth::kStale;
    reason_ = given_up ? std::string_view(never_reason_) : std::string_view(waiting_reason_);
  } else if (!(age_s <= options_.failed_after_s)) {
    health_ = DeviceHealth::kFailed;
    reason_ = failed_reason_;
  } else if (age_s > options_.stale_after_s) {
    health_ = DeviceHealth::kStale;
    reason_ = stale_reason_;
  } else {
    health_ = DeviceHealth::kConnected;
    reason_ = {};
  }
  const bool fresh = health_ == DeviceHealth::kConnected;
  for (std::size_t i = 0; i < newest_n_.size(); ++i) {
    rendered_.finger_force_n[i] = fresh ? newest_n_[i] : 0.0;
  }

  DeviceInput in;
  in.time_s = time_s;
  in.p_world = options_.p_world;
  in.q_world = options_.q_world;
  in.finger_count = kLegacyForceFingers;
  for (std::size_t i = 0; i < options_.finger_rad.size(); ++i) {
    in.finger_rad[i] = options_.finger_rad[i];
  }
  in.healthy = fresh;
  return in;
}

}  // namespace hapsim
