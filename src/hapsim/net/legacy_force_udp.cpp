#include "hapsim/net/legacy_force_udp.h"

#include "hapsim/core/error.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

namespace hapsim::net {
namespace {

std::string single_quoted(std::string_view text) {
  // Appended, not "'" + text + "'": GCC 12 warns (-Wrestrict, a false positive) on the latter.
  std::string out;
  out.reserve(text.size() + 2);
  out += '\'';
  out.append(text);
  out += '\'';
  return out;
}

std::uint16_t parse_port(std::string_view digits, std::string_view text, std::string_view option,
                         bool allow_zero) {
  const std::string range = allow_zero ? "0 to 65535" : "1 to 65535";
  if (digits.empty() || digits.size() > 5 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    throw Error(std::string(option),
                single_quoted(text) + ": the port must be a number from " + range);
  }
  const int port = std::stoi(std::string(digits));
  if (port > 65535 || (port == 0 && !allow_zero)) {
    throw Error(std::string(option),
                single_quoted(text) + ": the port must be a number from " + range);
  }
  return static_cast<std::uint16_t>(port);
}

// getaddrinfo's first answer for a UDP endpoint; throws one line when there is none.
struct Resolved {
  sockaddr_storage address{};
  socklen_t length = 0;
  int family = AF_UNSPEC;
};

Resolved resolve(const UdpEndpoint& endpoint, bool passive, std::string_view text,
                 std::string_view option) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICSERV | (passive ? AI_PASSIVE : 0);
  addrinfo* found = nullptr;
  const std::string port = std::to_string(endpoint.port);
  const int rc = getaddrinfo(endpoint.host.c_str(), port.c_str(), &hints, &found);
  if (rc != 0 || found == nullptr) {
    throw Error(std::string(option), single_quoted(text) + ": cannot resolve host " +
                                         single_quoted(endpoint.host) + " (" + gai_strerror(rc) +
                                         ")");
  }
  Resolved r;
  r.family = found->ai_family;
  r.length = found->ai_addrlen;
  std::memcpy(&r.address, found->ai_addr, found->ai_addrlen);
  freeaddrinfo(found);
  return r;
}

int open_udp_socket(int family, std::string_view text, std::string_view option) {
  const int fd = ::socket(family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    throw Error(std::string(option),
                single_quoted(text) + ": cannot open a UDP socket (" + std::strerror(errno) + ")");
  }
  return fd;
}

}  // namespace

UdpEndpoint parse_udp_endpoint(std::string_view text, std::string_view option,
                               std::string_view default_host, bool allow_port_zero) {
  const std::string expected = ": expected HOST:PORT or PORT, e.g. 127.0.0.1:5005";
  if (text.empty()) {
    throw Error(std::string(option), single_quoted(text) + expected);
  }
  UdpEndpoint endpoint;
  if (text.front() == '[') {  // [IPv6]:PORT
    const std::size_t close = text.find("]:");
    if (close == std::string_view::npos || close == 1) {
      throw Error(std::string(option), single_quoted(text) + expected);
    }
    endpoint.host = std::string(text.substr(1, close - 1));
    endpoint.port = parse_port(text.substr(close + 2), text, option, allow_port_zero);
    return endpoint;
  }
  const std::size_t colon = text.rfind(':');
  if (colon == std::string_view::npos) {
    if (!std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      throw Error(std::string(option), single_quoted(text) + expected);
    }
    endpoint.host = std::string(default_host);
    endpoint.port = parse_port(text, text, option, allow_port_zero);
    return endpoint;
  }
  const std::string_view host = text.substr(0, colon);
  if (host.empty()) {
    throw Error(std::string(option), single_quoted(text) + expected);
  }
  if (host.find(':') != std::string_view::npos) {
    throw Error(std::string(option),
                single_quoted(text) + ": write an IPv6 address in brackets, e.g. [::1]:5005");
  }
  endpoint.host = std::string(host);
  endpoint.port = parse_port(text.substr(colon + 1), text, option, allow_port_zero);
  return endpoint;
}

LegacyForceUdpSender::LegacyForceUdpSender(std::string_view host_port, std::string_view option)
    : destination_(parse_udp_endpoint(host_port, option)) {
  const Resolved r = resolve(destination_, false, host_port, option);
  fd_ = open_udp_socket(r.family, host_port, option);
  address_ = r.address;
  address_length_ = r.length;
}

LegacyForceUdpSender::~LegacyForceUdpSender() {
  ::close(fd_);
}

// haptic path
bool LegacyForceUdpSender::send(const LegacyForcePacket& packet) noexcept {
  // MSG_DONTWAIT: a full socket buffer drops this cycle's packet rather than waiting (the next
  // cycle sends a newer one). MSG_NOSIGNAL: no SIGPIPE, ever.
  const ssize_t n = ::sendto(fd_, packet.data(), packet.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
                             reinterpret_cast<const sockaddr*>(&address_), address_length_);
  if (n != static_cast<ssize_t>(packet.size())) {
    ++counts_.send_failed;
    return false;
  }
  ++counts_.sent;
  return true;
}

// haptic path
bool LegacyForceUdpSender::send_fingers(const LegacyFingerForces& finger_force_n,
                                        double finger_max_n) noexcept {
  const LegacyEncoded encoded = encode_legacy_force(finger_force_n, finger_max_n);
  counts_.clamped_fingers += static_cast<std::uint64_t>(encoded.clamped_fingers);
  return send(encoded.packet);
}

// haptic path
bool LegacyForceUdpSender::send_command(const DeviceCommand& command,
                                        double finger_max_n) noexcept {
  LegacyFingerForces fingers{};
  const int n = std::clamp(command.finger_count, 0, kLegacyForceFingers);
  for (int i = 0; i < n; ++i) {
    fingers[static_cast<std::size_t>(i)] = command.finger_force_n[static_cast<std::size_t>(i)];
  }
  return send_fingers(fingers, finger_max_n);
}

LegacyForceUdpReceiver::LegacyForceUdpReceiver(std::string_view spec, std::string_view option) {
  const std::size_t at = spec.find('@');
  const std::string_view bind_spec = spec.substr(0, at);
  const std::string_view peer_spec =
      at == std::string_view::npos ? std::string_view{} : spec.substr(at + 1);
  const UdpEndpoint wanted = parse_udp_endpoint(bind_spec, option, "127.0.0.1", true);
  const Resolved r = resolve(wanted, true, bind_spec, option);
  fd_ = open_udp_socket(r.family, bind_spec, option);
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&r.address), r.length) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw Error(std::string(option), single_quoted(bind_spec) + ": cannot bind UDP " + wanted.host +
                                         ":" + std::to_string(wanted.port) + " (" + why + ")");
  }
  sockaddr_storage actual{};
  socklen_t length = sizeof actual;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&actual), &length);
  char host[NI_MAXHOST] = {};
  char port[NI_MAXSERV] = {};
  ::getnameinfo(reinterpret_cast<const sockaddr*>(&actual), length, host, sizeof host, port,
                sizeof port, NI_NUMERICHOST | NI_NUMERICSERV);
  bound_.host = host;
  bound_.port = static_cast<std::uint16_t>(std::atoi(port));

  if (at != std::string_view::npos) {
    // "HOST" or "HOST:PORT" ("[IPV6]:PORT"): a bare name or address is any port of that host.
    const bool has_port = peer_spec.rfind("]:") != std::string_view::npos ||
                          (peer_spec.find(':') != std::string_view::npos &&
                           peer_spec.find(':') == peer_spec.rfind(':') && peer_spec.front() != '[');
    if (has_port) {
      peer_ = parse_udp_endpoint(peer_spec, option);
    } else if (!peer_spec.empty()) {
      const bool bracketed = peer_spec.front() == '[' && peer_spec.back() == ']';
      peer_.host = std::string(bracketed ? peer_spec.substr(1, peer_spec.size() - 2) : peer_spec);
    }
    if (peer_.host.empty()) {
      ::close(fd_);
      throw Error(std::string(option), single_quoted(spec) + ": name the force host after '@'");
    }
    peer_address_ = resolve(peer_, false, spec, option).address;
  } else if (r.family == AF_INET &&
             (ntohl(reinterpret_cast<const sockaddr_in&>(r.address).sin_addr.s_addr) >> 24) ==
                 127) {
    peer_ = {bound_.host, 0};  // loopback: this machine's own datagrams only
    peer_address_ = r.address;
  } else if (r.family == AF_INET6 &&
             IN6_IS_ADDR_LOOPBACK(&reinterpret_cast<const sockaddr_in6&>(r.address).sin6_addr)) {
    peer_ = {bound_.host, 0};
    peer_address_ = r.address;
  } else {
    ::close(fd_);
    throw Error(std::string(option),
                single_quoted(spec) + ": bound to " + bound_.host +
                    ", it would take force packets from anyone on the network; name the force "
                    "host: " +
                    std::string(bind_spec) + "@HOST");
  }
}

// haptic path
bool LegacyForceUdpReceiver::from_peer(const sockaddr_storage& source) const noexcept {
  if (source.ss_family == AF_INET && peer_address_.ss_family == AF_INET) {
    const auto& s = reinterpret_cast<const sockaddr_in&>(source);
    const auto& p = reinterpret_cast<const sockaddr_in&>(peer_address_);
    return s.sin_addr.s_addr == p.sin_addr.s_addr &&
           (peer_.port == 0 || ntohs(s.sin_port) == peer_.port);
  }
  if (source.ss_family == AF_INET6 && peer_address_.ss_family == AF_INET6) {
    const auto& s = reinterpret_cast<const sockaddr_in6&>(source);
    const auto& p = reinterpret_cast<const sockaddr_in6&>(peer_address_);
    return std::memcmp(&s.sin6_addr, &p.sin6_addr, sizeof s.sin6_addr) == 0 &&
           (peer_.port == 0 || ntohs(s.sin6_port) == peer_.port);
  }
  return false;
}

LegacyForceUdpReceiver::~LegacyForceUdpReceiver() {
  ::close(fd_);
}

// haptic path
std::optional<std::size_t> LegacyForceUdpReceiver::receive(std::span<std::byte> buffer) noexcept {
  // A flood from another sender is dropped a bounded number at a time: the cycle must not spin.
  constexpr int kMaxDroppedPerCall = 64;
  for (int dropped = 0; dropped < kMaxDroppedPerCall;) {
    // MSG_TRUNC: the datagram's real length even when it did not fit, so a long one is seen as
    // long; MSG_DONTWAIT: nothing pending is an answer, not a wait.
    sockaddr_storage source{};
    socklen_t source_length = sizeof source;
    const ssize_t n = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_DONTWAIT | MSG_TRUNC,
                                 reinterpret_cast<sockaddr*>(&source), &source_length);
    if (n >= 0 && !from_peer(source)) {
      ++other_senders_;  // dropped: the force comes from the force host only
      ++dropped;
      continue;
    }
    if (n >= 0) {
      ++datagrams_;
      return static_cast<std::size_t>(n);
    }
    if (errno == EINTR) {
      continue;
    }
    if (errno != EAGAIN && errno != EWOULDBLOCK) {
      ++errors_;
    }
    return std::nullopt;
  }
  return std::nullopt;
}

std::unique_ptr<LegacyGloveDevice> open_legacy_glove_udp(std::string_view bind_spec,
                                                         DeviceProfile profile,
                                                         const LegacyGloveOptions& options,
                                                         std::string_view option) {
  return std::make_unique<LegacyGloveDevice>(
      std::move(profile), std::make_unique<LegacyForceUdpReceiver>(bind_spec, option), options);
}

}  // namespace hapsim::net
