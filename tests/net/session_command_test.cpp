// The Command topic's gate and encoding (net/session_command.h): what an issuer encodes the host
// decodes to the same command; every kind of bad command gets its own verdict and is counted; a
// material change sets only the fields it names.
#include "hapsim/net/session_command.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

constexpr std::uint64_t kHash = 0xfeedULL;
constexpr std::uint64_t kServe = 0xabcULL;
constexpr std::size_t kMaterials = 3;

SessionCommand material_command() {
  SessionCommand c;
  c.kind = SessionCommandKind::kSetMaterial;
  c.material = 2;
  c.material_fields = material_field::kStiffness | material_field::kDynamicFriction;
  c.contact.stiffness_n_per_m = 750.0;
  c.contact.dynamic_friction = 0.25;
  return c;
}

TEST(SessionCommand, NamesRoundTrip) {
  for (const SessionCommandKind k :
       {SessionCommandKind::kPause, SessionCommandKind::kResume, SessionCommandKind::kReset,
        SessionCommandKind::kSetMaterial}) {
    EXPECT_EQ(command_kind(command_name(k)), k);
  }
  EXPECT_FALSE(command_kind("pauze").has_value());
  EXPECT_FALSE(command_kind("").has_value());
}

TEST(SessionCommand, AnEncodedCommandIsAdmittedAsItWasSent) {
  CommandGate gate(kHash, kServe, kMaterials);
  SessionCommand out;
  ASSERT_EQ(gate.admit(encode_session_command(material_command(), 7, 1, kHash, kServe), out),
            SampleVerdict::kAccepted);
  EXPECT_EQ(out.kind, SessionCommandKind::kSetMaterial);
  EXPECT_EQ(out.material, 2u);
  EXPECT_EQ(out.material_fields, material_command().material_fields);
  EXPECT_EQ(out.contact.stiffness_n_per_m, 750.0);
  EXPECT_EQ(out.contact.dynamic_friction, 0.25);

  SessionCommand reset;
  reset.kind = SessionCommandKind::kReset;
  ASSERT_EQ(gate.admit(encode_session_command(reset, 7, 2, kHash, kServe), out),
            SampleVerdict::kAccepted);
  EXPECT_EQ(out.kind, SessionCommandKind::kReset);
  EXPECT_EQ(gate.count(SampleVerdict::kAccepted), 2u);
}

TEST(SessionCommand, OnlyTheNamedFieldsChange) {
  ContactMaterial current;
  current.stiffness_n_per_m = 1500.0;
  current.max_penetration_m = 0.004;
  current.max_force_n = 6.0;
  current.damping_n_s_per_m = 1.0;
  current.static_friction = 0.4;
  current.dynamic_friction = 0.3;
  const ContactMaterial c = apply_material_fields(current, material_command());
  EXPECT_EQ(c.stiffness_n_per_m, 750.0);
  EXPECT_EQ(c.dynamic_friction, 0.25);
  EXPECT_EQ(c.max_penetration_m, 0.004);
  EXPECT_EQ(c.max_force_n, 6.0);
  EXPECT_EQ(c.damping_n_s_per_m, 1.0);
  EXPECT_EQ(c.static_friction, 0.4);
}

// A flood of made-up issuers (anyone on the network can publish commands) must not lock out a
// live issuer's Pause: with the table full, each newcomer evicts the issuer heard from least
// recently, so the live one, if evicted, is heard again as new. Memory stays bounded.
TEST(SessionCommand, TwoThousandFakeIssuersDoNotBlockAPause) {
  CommandGate gate(kHash, kServe, kMaterials);  // 1024 issuers remembered
  SessionCommand out;
  SessionCommand pause;
  pause.kind = SessionCommandKind::kPause;
  const std::uint64_t live = 0xC0FFEE;
  ASSERT_EQ(gate.admit(encode_session_command(pause, live, 1, kHash, kServe), out),
            SampleVerdict::kAccepted);
  for (std::uint64_t fake = 1; fake <= 2000; ++fake) {
    ASSERT_EQ(gate.admit(encode_session_command(material_command(), fake, 1, kHash, kServe), out),
              SampleVerdict::kAccepted)
        << fake;
  }
  EXPECT_EQ(gate.evicted_issuers(), 2001u - 1024u);
  out = SessionCommand{};
  EXPECT_EQ(gate.admit(encode_session_command(pause, live, 2, kHash, kServe), out),
            SampleVerdict::kAccepted);
  EXPECT_EQ(out.kind, SessionCommandKind::kPause);
}

TEST(SessionCommand, EachBadCommandHasItsVerdictAndIsCounted) {
  CommandGate gate(kHash, kServe, kMaterials, CommandLimits{.max_issuers = 2});
  SessionCommand out;
  SessionCommand pause;
  const auto admit = [&](const hapsim_msg_Command& m) { return gate.admit(m, out); };
  const auto good = [&](std::uint64_t issuer, std::uint64_t seq) {
    return encode_session_command(material_command(), issuer, seq, kHash, kServe);
  };

  ASSERT_EQ(admit(good(1, 5)), SampleVerdict::kAccepted);
  EXPECT_EQ(admit(good(1, 5)), SampleVerdict::kOutOfOrder);  // a duplicate
  EXPECT_EQ(admit(good(1, 4)), SampleVerdict::kOutOfOrder);  // an older one
  EXPECT_EQ(admit(good(2, 1)), SampleVerdict::kAccepted);    // another issuer counts its own
  // One issuer too many takes the place of the one heard from least recently (issuer 1), whose
  // order is forgotten: its old command is news again.
  EXPECT_EQ(admit(good(3, 1)), SampleVerdict::kAccepted);
  EXPECT_EQ(gate.evicted_issuers(), 1u);
  EXPECT_EQ(admit(good(2, 1)), SampleVerdict::kOutOfOrder);  // issuer 2 is remembered
  EXPECT_EQ(admit(good(1, 4)), SampleVerdict::kAccepted);    // issuer 1 was not
  EXPECT_EQ(admit(encode_session_command(pause, 1, 9, kHash ^ 1U, kServe)),
            SampleVerdict::kOtherScene);
  EXPECT_EQ(admit(encode_session_command(pause, 1, 9, kHash, kServe + 1)),
            SampleVerdict::kStale);  // for another start of the host

  hapsim_msg_Command m = good(1, 10);
  m.kind = 0;
  EXPECT_EQ(admit(m), SampleVerdict::kMalformed);
  m = good(1, 10);
  m.kind = 5;
  EXPECT_EQ(admit(m), SampleVerdict::kMalformed);
  m = good(1, 10);
  m.material = kMaterials;
  EXPECT_EQ(admit(m), SampleVerdict::kMalformed);
  m = good(1, 10);
  m.material_fields = 1U << 6;
  EXPECT_EQ(admit(m), SampleVerdict::kMalformed);
  m = good(1, 10);
  m.material_fields = 0;
  EXPECT_EQ(admit(m), SampleVerdict::kMalformed);
  m = good(1, 10);
  m.stiffness_n_per_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(admit(m), SampleVerdict::kMalformed);
  m = good(1, 10);
  m.dynamic_friction = std::numeric_limits<double>::infinity();
  EXPECT_EQ(admit(m), SampleVerdict::kMalformed);
  m = good(1, 10);
  m.stiffness_n_per_m = -1.0;
  EXPECT_EQ(admit(m), SampleVerdict::kOutOfRange);
  m = good(1, 10);
  m.stiffness_n_per_m = 2e6;
  EXPECT_EQ(admit(m), SampleVerdict::kOutOfRange);
  // A value the command does not set is not looked at.
  m = good(1, 10);
  m.max_force_n = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(admit(m), SampleVerdict::kAccepted);
  // Nothing refused moved the issuer's newest sequence.
  EXPECT_EQ(admit(good(1, 10)), SampleVerdict::kOutOfOrder);
  EXPECT_EQ(admit(good(1, 11)), SampleVerdict::kAccepted);

  EXPECT_EQ(gate.count(SampleVerdict::kAccepted), 6u);
  EXPECT_EQ(gate.count(SampleVerdict::kOutOfOrder), 4u);
  EXPECT_EQ(gate.count(SampleVerdict::kOutOfRange), 2u);
  EXPECT_EQ(gate.count(SampleVerdict::kMalformed), 7u);
  EXPECT_EQ(gate.count(SampleVerdict::kOtherScene), 1u);
  EXPECT_EQ(gate.count(SampleVerdict::kStale), 1u);
}

}  // namespace
}  // namespace hapsim::net
