// A typed DDS reader on its topic with the topic's QoS (net/topics.h), in a participant's
// session. take() never blocks and takes into the caller's own storage (no loans, no allocation
// for fixed-size types): the haptic loop calls it once a cycle. No listener callbacks: they run
// on Cyclone's threads (STACK.md).
#pragma once

#include "hapsim/net/dds_entity.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/topics.h"

#include <array>
#include <cstddef>
#include <cstdint>

namespace hapsim::net {

template <typename T>
class TopicReader {
 public:
  /// At most this many samples per take() (one per key is the steady state).
  static constexpr std::size_t kMaxTake = 8;

  explicit TopicReader(const Participant& participant) {
    reader_ = create_reader<T>(participant, topic_);
  }

  /// Takes what has arrived (at most kMaxTake samples) without blocking and calls
  /// on_sample(const T&, const dds_sample_info_t&) for each one with data, oldest first per key.
  /// Returns how many it passed on. haptic path
  template <typename OnSample>
  std::size_t take(OnSample&& on_sample) noexcept {
    std::array<void*, kMaxTake> pointers{};
    for (std::size_t i = 0; i < kMaxTake; ++i) {
      pointers[i] = &buffer_[i];
    }
    const dds_return_t n =
        dds_take(reader_.get(), pointers.data(), infos_.data(), kMaxTake, kMaxTake);
    if (n < 0) {
      ++failed_;
      return 0;
    }
    std::size_t passed = 0;
    for (dds_return_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (infos_[k].valid_data) {
        on_sample(buffer_[k], infos_[k]);
        ++passed;
      }
    }
    return passed;
  }

  [[nodiscard]] std::uint32_t matched_writers() const {
    dds_subscription_matched_status_t status{};
    check_dds(dds_get_subscription_matched_status(reader_.get(), &status), "matched writers");
    return status.current_count;
  }
  [[nodiscard]] std::uint64_t failed_takes() const noexcept { return failed_; }
  /// For a waitset on a thread that may block (never the haptic one).
  [[nodiscard]] dds_entity_t handle() const noexcept { return reader_.get(); }

 private:
  DdsEntity topic_;
  DdsEntity reader_;
  std::array<T, kMaxTake> buffer_{};
  std::array<dds_sample_info_t, kMaxTake> infos_{};
  std::uint64_t failed_ = 0;
};

}  // namespace hapsim::net
