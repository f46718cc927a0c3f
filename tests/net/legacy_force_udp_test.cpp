// The legacy force packet over real UDP on loopback: HOST:PORT parsing (one line per mistake),
// the receiver bound to 127.0.0.1 by default, sender → socket → legacy glove rendering the newest
// packet (forces computed here from the paper's scaling), short and long datagrams counted, and
// send and poll allocating nothing.
#include "hapsim/net/legacy_force_udp.h"

#include "hapsim/core/error.h"
#include "support/allocation_counter.h"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>
#include <vector>

namespace hapsim::net {
namespace {

std::string parse_error(std::string_view text, bool allow_zero = false) {
  try {
    (void)parse_udp_endpoint(text, "--legacy-force-udp", "127.0.0.1", allow_zero);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(LegacyForceUdp, ParsesHostPortForms) {
  UdpEndpoint e = parse_udp_endpoint("10.0.0.7:5005", "--x");
  EXPECT_EQ(e.host, "10.0.0.7");
  EXPECT_EQ(e.port, 5005);
  e = parse_udp_endpoint("6000", "--x");
  EXPECT_EQ(e.host, "127.0.0.1");  // loopback unless told
  EXPECT_EQ(e.port, 6000);
  e = parse_udp_endpoint("forcehost.lab:7000", "--x");
  EXPECT_EQ(e.host, "forcehost.lab");
  e = parse_udp_endpoint("[::1]:7001", "--x");
  EXPECT_EQ(e.host, "::1");
  EXPECT_EQ(e.port, 7001);
  EXPECT_EQ(parse_udp_endpoint("0", "--x", "127.0.0.1", true).port, 0);
}

TEST(LegacyForceUdp, AMalformedEndpointIsOneLineNamingTheOption) {
  for (const char* bad : {"", "forcehost", "forcehost:", ":5005", "h:65536", "h:12a", "h:0",
                          "::1:5005", "[::1]5005", "[]:5005"}) {
    const std::string message = parse_error(bad);
    EXPECT_EQ(message.rfind("--legacy-force-udp: '" + std::string(bad) + "': ", 0), 0U) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_NE(parse_error("h:70000").find("the port must be a number from 1 to 65535"),
            std::string::npos);
  EXPECT_NE(parse_error("::1:5005").find("in brackets"), std::string::npos);
}

TEST(LegacyForceUdp, ReceiverBindsLoopbackUnlessTold) {
  LegacyForceUdpReceiver receiver("0");
  EXPECT_EQ(receiver.bound().host, "127.0.0.1");
  EXPECT_NE(receiver.bound().port, 0);
  EXPECT_EQ(receiver.peer().host, "127.0.0.1");  // its own machine's datagrams only
  // Every interface: only with the force host named, or anyone on the network could push force.
  LegacyForceUdpReceiver explicit_any("0.0.0.0:0@127.0.0.1");
  EXPECT_EQ(explicit_any.bound().host, "0.0.0.0");
  EXPECT_EQ(explicit_any.peer().host, "127.0.0.1");
  try {
    LegacyForceUdpReceiver open_to_all("0.0.0.0:0");
    FAIL() << "bound every interface without a force host";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("--legacy-force-bind: '0.0.0.0:0': ", 0), 0U) << what;
    EXPECT_NE(what.find("0.0.0.0:0@HOST"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(LegacyForceUdpReceiver("0@"), Error);
  // A port someone holds: one line, naming the option.
  try {
    LegacyForceUdpReceiver twice(std::to_string(receiver.bound().port));
    FAIL() << "bound a port twice";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--legacy-force-bind: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cannot bind UDP"), std::string::npos) << e.what();
  }
}

// Reads the glove until `accepted` packets were judged valid or a second passed (loopback
// delivers at once; the wait only guards a loaded machine).
void read_until(LegacyGloveDevice& glove, std::uint64_t judged, double& t) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (true) {
    (void)glove.read(t);
    std::uint64_t total = 0;
    for (const std::uint64_t c : glove.counts()) {
      total += c;
    }
    if (total >= judged || std::chrono::steady_clock::now() > give_up) {
      return;
    }
    t += 1e-4;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

TEST(LegacyForceUdp, SenderToGloveRendersTheNewestPacket) {
  auto receiver = std::make_unique<LegacyForceUdpReceiver>("0");
  const std::string destination = "127.0.0.1:" + std::to_string(receiver->bound().port);
  LegacyGloveDevice device(device_profile("rutgers_master"), std::move(receiver));
  LegacyForceUdpSender sender(destination);

  // The paper's scaling: value = round(1000 × f / f_max × 10); the glove's f_max is 4 N.
  EXPECT_TRUE(sender.send_fingers({1.0, 0.0, 0.0, 0.0}, 4.0));
  EXPECT_TRUE(sender.send_fingers({0.5, 1.5, 3.0, 9.0}, 4.0));  // the last one clamped to 4 N
  DeviceCommand c;
  c.finger_count = 5;
  c.finger_force_n = {0.25, 0.5, 1.0, 2.0, 3.0};  // the fifth finger is not in the packet
  EXPECT_TRUE(sender.send_command(c, 4.0));
  EXPECT_EQ(sender.counts().sent, 3U);
  EXPECT_EQ(sender.counts().clamped_fingers, 1U);

  double t = 0.0;
  read_until(device, 3, t);
  EXPECT_EQ(device.count(LegacyPacketVerdict::kAccepted), 3U);
  EXPECT_EQ(device.newest_finger_force_n(), (LegacyFingerForces{0.25, 0.5, 1.0, 2.0}));
  EXPECT_EQ(device.rendered().finger_force_n[3], 2.0);
  EXPECT_EQ(device.status().health, DeviceHealth::kConnected);
}

TEST(LegacyForceUdp, OpensTheLegacyGloveOnLoopback) {
  const std::unique_ptr<LegacyGloveDevice> glove = open_legacy_glove_udp("0");
  EXPECT_EQ(glove->profile().name, "rutgers_master");
  EXPECT_FALSE(glove->read(0.0).healthy);  // nothing sent yet
  EXPECT_THROW((void)open_legacy_glove_udp("glove"), Error);
}

TEST(LegacyForceUdp, ShortAndLongDatagramsAreCountedNotApplied) {
  auto receiver = std::make_unique<LegacyForceUdpReceiver>("0");
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(receiver->bound().port);
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  LegacyGloveDevice device(device_profile("rutgers_master"), std::move(receiver));
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  const std::vector<std::byte> short_one(15, std::byte{0});
  const std::vector<std::byte> long_one(1500, std::byte{0});
  const std::vector<std::byte> empty;
  for (const auto* d : {&short_one, &long_one, &empty}) {
    ASSERT_EQ(
        ::sendto(fd, d->data(), d->size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to),
        static_cast<ssize_t>(d->size()));
  }
  ::close(fd);
  double t = 0.0;
  read_until(device, 3, t);
  EXPECT_EQ(device.count(LegacyPacketVerdict::kShort), 2U);  // 15 bytes and an empty datagram
  EXPECT_EQ(device.count(LegacyPacketVerdict::kLong), 1U);
  EXPECT_EQ(device.count(LegacyPacketVerdict::kAccepted), 0U);
  EXPECT_FALSE(device.newest_received_s().has_value());
  EXPECT_EQ(device.status().health, DeviceHealth::kStale);
}

// Sends `count` valid packets (1 N on the first finger) to `port` from a socket bound to
// `source_ip` (every 127/8 address is this machine's loopback).
void send_from(const char* source_ip, std::uint16_t port, int count) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in from{};
  from.sin_family = AF_INET;
  ASSERT_EQ(::inet_pton(AF_INET, source_ip, &from.sin_addr), 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&from), sizeof from), 0) << source_ip;
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const LegacyForcePacket packet = encode_legacy_force({1.0, 0.0, 0.0, 0.0}, 4.0).packet;
  for (int i = 0; i < count; ++i) {
    ASSERT_EQ(::sendto(fd, packet.data(), packet.size(), 0, reinterpret_cast<const sockaddr*>(&to),
                       sizeof to),
              static_cast<ssize_t>(packet.size()));
  }
  ::close(fd);
}

// Anyone who reaches the port can send a well-formed packet: the glove takes force only from its
// force host, and counts the others (issue 32). Spoofed packets from another address (127.0.0.2)
// are dropped before they are read; the force host's own (127.0.0.1) are rendered.
TEST(LegacyForceUdp, PacketsFromAnotherSenderAreCountedAndIgnored) {
  auto receiver = std::make_unique<LegacyForceUdpReceiver>("0");
  const std::uint16_t port = receiver->bound().port;
  LegacyGloveDevice device(device_profile("rutgers_master"), std::move(receiver));
  send_from("127.0.0.2", port, 5);
  double t = 0.0;
  for (int i = 0; i < 200 && device.count(LegacyPacketVerdict::kOtherSender) < 5; ++i) {
    (void)device.read(t);
    t += 1e-3;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(device.count(LegacyPacketVerdict::kOtherSender), 5U);
  EXPECT_EQ(device.count(LegacyPacketVerdict::kAccepted), 0U);
  EXPECT_FALSE(device.newest_received_s().has_value());
  send_from("127.0.0.1", port, 1);
  read_until(device, 6, t);
  EXPECT_EQ(device.count(LegacyPacketVerdict::kAccepted), 1U);
  EXPECT_EQ(device.newest_finger_force_n()[0], 1.0);

  // Told to take another host's packets, it takes those only.
  auto other = std::make_unique<LegacyForceUdpReceiver>("0@127.0.0.2");
  const std::uint16_t other_port = other->bound().port;
  LegacyGloveDevice told(device_profile("rutgers_master"), std::move(other));
  send_from("127.0.0.1", other_port, 2);
  send_from("127.0.0.2", other_port, 1);
  read_until(told, 3, t);
  EXPECT_EQ(told.count(LegacyPacketVerdict::kOtherSender), 2U);
  EXPECT_EQ(told.count(LegacyPacketVerdict::kAccepted), 1U);
}

TEST(LegacyForceUdp, SendAndPollAllocateNothing) {
  auto receiver = std::make_unique<LegacyForceUdpReceiver>("0");
  LegacyForceUdpSender sender("127.0.0.1:" + std::to_string(receiver->bound().port));
  LegacyGloveDevice device(device_profile("rutgers_master"), std::move(receiver));
  DeviceCommand c;
  c.finger_count = 4;
  (void)sender.send_command(c, 4.0);
  (void)device.read(0.0);
  const long before = hapsim::test::thread_allocation_count();
  for (int i = 0; i < 1000; ++i) {
    c.finger_force_n[0] = 1e-3 * i;
    (void)sender.send_command(c, 4.0);
    (void)device.read(1e-3 * i);
  }
  EXPECT_EQ(hapsim::test::thread_allocation_count() - before, 0);
  EXPECT_GT(device.count(LegacyPacketVerdict::kAccepted), 0U);
}

}  // namespace
}  // namespace hapsim::net
