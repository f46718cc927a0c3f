// A typed DDS writer on its topic with the topic's QoS (net/topics.h), in a participant's
// session. write() is the haptic-path call: no allocation for fixed-size types, no throw.
#pragma once

#include "hapsim/net/dds_entity.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/topics.h"

#include <cstdint>

namespace hapsim::net {

template <typename T>
class TopicWriter {
 public:
  explicit TopicWriter(const Participant& participant) {
    Qos qos;
    apply_profile(qos, TopicTraits<T>::kQos);
    topic_ = create_topic<T>(participant, qos);
    writer_ = DdsEntity(
        check_dds(dds_create_writer(participant.publisher(), topic_.get(), qos.get(), nullptr),
                  std::string("creating a writer on ") + TopicTraits<T>::kName));
  }

  /// False (and counted) when Cyclone refuses the sample. haptic path
  bool write(const T& sample) noexcept {
    if (dds_write(writer_.get(), &sample) < 0) {
      ++failed_;
      return false;
    }
    return true;
  }

  /// Readers matched now (for a caller that waits for its peer before streaming).
  [[nodiscard]] std::uint32_t matched_readers() const {
    dds_publication_matched_status_t status{};
    check_dds(dds_get_publication_matched_status(writer_.get(), &status), "matched readers");
    return status.current_count;
  }
  [[nodiscard]] std::uint64_t failed_writes() const noexcept { return failed_; }
  /// Reliable topics: blocks until every matched reader acknowledged what was written, or
  /// `timeout_s` passed (false). Never on the haptic path.
  [[nodiscard]] bool wait_for_acks(double timeout_s) const noexcept {
    return dds_wait_for_acks(writer_.get(), static_cast<dds_duration_t>(timeout_s * 1e9)) ==
           DDS_RETCODE_OK;
  }

 private:
  DdsEntity topic_;
  DdsEntity writer_;
  std::uint64_t failed_ = 0;
};

}  // namespace hapsim::net
