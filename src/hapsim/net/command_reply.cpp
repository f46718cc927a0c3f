#include "hapsim/net/command_reply.h"

#include <cstdio>
#include <cstring>

namespace hapsim::net {

hapsim_msg_CommandReply encode_command_reply(const CommandReplySample& reply) {
  hapsim_msg_CommandReply m{};
  m.issuer_id = reply.issuer_id;
  m.command_sequence = reply.command_sequence;
  m.serve_id = reply.serve_id;
  m.accepted = reply.accepted;
  constexpr std::size_t kRoom = sizeof m.reason - 1;  // the NUL
  std::string reason = reply.reason;
  if (reason.size() > kRoom) {
    reason.resize(kRoom - 3);
    reason += "...";
  }
  std::memcpy(m.reason, reason.data(), reason.size());
  return m;
}

CommandReplySample decode_command_reply(const hapsim_msg_CommandReply& m) {
  CommandReplySample reply;
  reply.issuer_id = m.issuer_id;
  reply.command_sequence = m.command_sequence;
  reply.serve_id = m.serve_id;
  reply.accepted = m.accepted;
  for (const char c : m.reason) {
    if (c == '\0') {
      break;
    }
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", u);
      reply.reason += escaped;
    } else {
      reply.reason += c;
    }
  }
  return reply;
}

}  // namespace hapsim::net
