// The issuing side of the Command topic (net/session_command.h): one issuer (a viewer, an
// operator's `hapsim control`) sending numbered commands to one start of one simulation host,
// known from its SceneInfo. Off the haptic path.
#pragma once

#include "hapsim/net/participant.h"
#include "hapsim/net/scene_info.h"
#include "hapsim/net/session_command.h"
#include "hapsim/net/topic_writer.h"

#include <cstdint>

namespace hapsim::net {

class CommandSender {
 public:
  /// Commands for the host that published `host` (its scene hash and serve id).
  CommandSender(const Participant& participant, const SceneInfoSample& host)
      : writer_(participant),
        issuer_id_(draw_serve_id()),  // a fresh random id per issuing process
        scene_hash_(host.scene_hash),
        serve_id_(host.serve_id) {}

  /// Addresses the next commands to another start of a host (a viewer followed a restart).
  void retarget(const SceneInfoSample& host) noexcept {
    scene_hash_ = host.scene_hash;
    serve_id_ = host.serve_id;
  }

  /// False when Cyclone refused the sample.
  bool send(const SessionCommand& command) noexcept {
    return writer_.write(
        encode_session_command(command, issuer_id_, ++sequence_, scene_hash_, serve_id_));
  }
  /// Until the host acknowledged everything sent, or `timeout_s` (false).
  [[nodiscard]] bool wait_for_acks(double timeout_s) const noexcept {
    return writer_.wait_for_acks(timeout_s);
  }
  [[nodiscard]] std::uint32_t matched_hosts() const { return writer_.matched_readers(); }
  [[nodiscard]] std::uint64_t issuer_id() const noexcept { return issuer_id_; }
  /// The sequence number of the last command sent (its reply carries it).
  [[nodiscard]] std::uint64_t sequence() const noexcept { return sequence_; }

 private:
  TopicWriter<hapsim_msg_Command> writer_;
  std::uint64_t issuer_id_;
  std::uint64_t scene_hash_;
  std::uint64_t serve_id_;
  std::uint64_t sequence_ = 0;
};

}  // namespace hapsim::net
