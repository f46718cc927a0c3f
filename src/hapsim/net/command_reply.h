// A simulation host's answer to a Command (net/idl CommandReply): accepted, or refused and why.
// The transport's acknowledgement only says a command arrived; `hapsim control` waits for this
// to say whether the host took it, and prints the host's reason when it did not.
#pragma once

#include "hapsim_messages.h"

#include <cstdint>
#include <string>

namespace hapsim::net {

struct CommandReplySample {
  std::uint64_t issuer_id = 0;
  std::uint64_t command_sequence = 0;
  std::uint64_t serve_id = 0;
  bool accepted = false;
  std::string reason;  ///< "" when accepted
};

/// The message for `reply`; a reason longer than the message holds is cut (and says so).
[[nodiscard]] hapsim_msg_CommandReply encode_command_reply(const CommandReplySample& reply);

/// The reply `m` carries: the reason read up to its NUL (or the array's end), with control
/// characters escaped (\xNN): text from the network reaches a terminal.
[[nodiscard]] CommandReplySample decode_command_reply(const hapsim_msg_CommandReply& m);

}  // namespace hapsim::net
