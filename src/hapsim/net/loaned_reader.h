// A typed DDS reader for the topics whose samples hold strings or sequences (SceneInfo,
// ViewState): take() borrows Cyclone's own samples (a loan) and returns them, so nothing the
// middleware allocated is left for us to free. Off the haptic path only: a loaned take may
// allocate inside Cyclone. Never blocks.
#pragma once

#include "hapsim/net/dds_entity.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/topics.h"

#include <array>
#include <cstddef>
#include <cstdint>

namespace hapsim::net {

template <typename T>
class LoanedReader {
 public:
  static constexpr std::size_t kMaxTake = 4;

  explicit LoanedReader(const Participant& participant) {
    reader_ = create_reader<T>(participant, topic_);
  }

  /// Takes what has arrived and calls on_sample(const T&) for each sample with data, oldest
  /// first. Returns how many it passed on.
  template <typename OnSample>
  std::size_t take(OnSample&& on_sample) {
    std::array<void*, kMaxTake> samples{};  // null: Cyclone lends its own
    std::array<dds_sample_info_t, kMaxTake> infos{};
    const dds_return_t n = dds_take(reader_.get(), samples.data(), infos.data(), kMaxTake,
                                    static_cast<uint32_t>(kMaxTake));
    if (n <= 0) {
      failed_ += n < 0 ? 1 : 0;
      return 0;
    }
    std::size_t passed = 0;
    // Return the loan whatever on_sample does.
    struct Loan {
      dds_entity_t reader;
      std::array<void*, kMaxTake>& samples;
      dds_return_t n;
      ~Loan() { (void)dds_return_loan(reader, samples.data(), n); }
    } loan{reader_.get(), samples, n};
    for (dds_return_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (infos[k].valid_data) {
        on_sample(*static_cast<const T*>(samples[k]));
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

 private:
  DdsEntity topic_;
  DdsEntity reader_;
  std::uint64_t failed_ = 0;
};

}  // namespace hapsim::net
