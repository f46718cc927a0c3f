// Secure sessions (issue 32, docs/security.md): keys made by `hapsim keys`, a serve started with
// `--secure` and, beside it, what must be refused — a plain participant (a rogue publisher and
// reader built here from the project's IDL) neither receives a sample nor gets one accepted; a
// viewer identity's Command is refused by access control; a revoked device is refused at its
// handshake. Each refusal is checked beside something the same serve accepts in the same run (a
// secure watcher's views, an instructor's pause, another device's states), so progress, not a
// clock, says the refused one had its chance. And the key directory's own checks: a key readable
// by others, a certificate from another session's CA, a missing file, the wrong session.
#include "hapsim/core/error.h"
#include "hapsim/net/device_state_codec.h"
#include "hapsim/net/loaned_reader.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/security_config.h"
#include "hapsim/net/security_key_dir.h"
#include "hapsim/net/security_keys.h"
#include "hapsim/net/topic_reader.h"
#include "hapsim/net/topic_writer.h"

#include "apps/hapsim_process.h"
#include "net/net_test_support.h"

#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <regex>
#include <thread>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

constexpr dds_domainid_t kDomain = 85;
const std::string kScene = std::string(HAPSIM_SOURCE_DIR) + "/scenes/knee_procedural.json";

std::filesystem::path fresh_keys(const std::string& name, const std::string& session,
                                 const std::vector<std::string>& devices) {
  const std::filesystem::path dir = hapsim::test::temp_path(name);
  std::filesystem::remove_all(dir);
  (void)SecurityKeyDir::init(dir, session, devices);
  return dir;
}

std::string net_args(const std::string& session, const std::filesystem::path& keys) {
  return " --session " + session + " --domain " + std::to_string(kDomain) + " --secure " +
         keys.string();
}

// A log of its own for each process (with --gtest_repeat a reused name would be read before the
// new process truncated it).
std::filesystem::path fresh_log(const std::string& name) {
  static int count = 0;
  return hapsim::test::temp_path(name + "-" + std::to_string(++count) + ".log");
}

// The scene hash serve prints ("scene hash 0123456789abcdef").
std::uint64_t printed_hash(const std::string& serve_output) {
  std::smatch m;
  if (!std::regex_search(serve_output, m, std::regex("scene hash ([0-9a-f]{16})")))
    return 0;
  return std::strtoull(m[1].str().c_str(), nullptr, 16);
}

TEST(SecureSession, APlainParticipantNeitherReceivesNorGetsAnythingAccepted) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::string session = "secure-plain";
  const auto keys = fresh_keys("keys-plain", session, {"device"});
  hapsim::test::BackgroundHapsim serve("serve " + kScene + net_args(session, keys),
                                       fresh_log("secure-plain-serve"));
  ASSERT_TRUE(serve.wait_for("security     SECURE", std::chrono::seconds(30))) << serve.output();
  const std::uint64_t hash = printed_hash(serve.output());
  ASSERT_NE(hash, 0u) << serve.output();

  // The rogue: plain DDS in the same domain and partition, reading everything serve publishes and
  // writing device states a plain serve would accept (the right scene hash, device 0, in order).
  Participant rogue(kDomain, session);
  LoanedReader<hapsim_msg_SceneInfo> info_in(rogue);
  LoanedReader<hapsim_msg_ViewState> views_in(rogue);
  TopicReader<hapsim_msg_LocalModel> models_in(rogue);
  TopicWriter<hapsim_msg_DeviceState> states_out(rogue);
  std::atomic<bool> done{false};
  std::size_t received = 0;
  std::uint64_t sent = 0;
  std::thread rogue_loop([&] {
    while (!done.load()) {
      DeviceStateSample s;
      s.device_id = 0;
      s.sequence = ++sent;
      s.input.p_world = Vec3(0.0, 0.0, 0.05);
      (void)states_out.write(encode_device_state(s, hash));
      received += info_in.take([](const hapsim_msg_SceneInfo&) {});
      received += views_in.take([](const hapsim_msg_ViewState&) {});
      received += models_in.take([](const hapsim_msg_LocalModel&, const dds_sample_info_t&) {});
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  // Meanwhile a secure viewer sees the served world: the session works for those it admits.
  const hapsim::test::RunResult watched =
      hapsim::test::run_hapsim("watch --duration 2 --wait 60" + net_args(session, keys));
  done = true;
  rogue_loop.join();
  EXPECT_EQ(watched.exit_code, 0) << watched.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(watched.output, m, std::regex("views +([0-9]+) in")))
      << watched.output;
  EXPECT_GT(std::stoul(m[1].str()), 10u) << watched.output;

  EXPECT_GT(sent, 100u);
  EXPECT_EQ(received, 0u) << "a plain participant received samples of a secure session";
  serve.signal(SIGINT);
  EXPECT_EQ(serve.wait(), 130) << serve.output();
  EXPECT_EQ(serve.output().find("device host  joined"), std::string::npos) << serve.output();
  EXPECT_TRUE(std::regex_search(serve.output(), std::regex("states: accepted 0,")))
      << serve.output();
}

TEST(SecureSession, AViewersCommandIsRefusedByAccessControl) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::string session = "secure-viewer";
  const auto keys = fresh_keys("keys-viewer", session, {"device"});
  hapsim::test::BackgroundHapsim serve("serve " + kScene + net_args(session, keys),
                                       fresh_log("secure-viewer-serve"));
  ASSERT_TRUE(serve.wait_for("security     SECURE", std::chrono::seconds(30))) << serve.output();

  const hapsim::test::RunResult as_viewer = hapsim::test::run_hapsim(
      "control pause --timeout 60 --identity viewer" + net_args(session, keys));
  EXPECT_EQ(as_viewer.exit_code, 2) << as_viewer.output;
  EXPECT_NE(as_viewer.output.find("hapsim_command: Not Allowed By Security"), std::string::npos)
      << as_viewer.output;
  // The instructor's pause is taken: serve never received the viewer's.
  const hapsim::test::RunResult as_instructor =
      hapsim::test::run_hapsim("control pause --timeout 60" + net_args(session, keys));
  EXPECT_EQ(as_instructor.exit_code, 0) << as_instructor.output;
  EXPECT_NE(as_instructor.output.find("is paused"), std::string::npos) << as_instructor.output;
  // (A paused serve does not stop on SIGINT: resumed first.)
  const hapsim::test::RunResult resumed =
      hapsim::test::run_hapsim("control resume --timeout 60" + net_args(session, keys));
  EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
  serve.signal(SIGINT);
  EXPECT_EQ(serve.wait(), 130) << serve.output();
  EXPECT_TRUE(std::regex_search(serve.output(), std::regex("commands     2 received: accepted 2")))
      << serve.output();
}

TEST(SecureSession, ARevokedDeviceIsRefusedAtItsHandshake) {
  ASSERT_TRUE(test::on_loopback_config());
  const std::string session = "secure-revoked";
  const auto keys = fresh_keys("keys-revoked", session, {"hostA", "hostB"});
  // hostA keeps its copy of the keys from before the revocation (what a stolen laptop holds).
  const std::filesystem::path stolen = hapsim::test::temp_path("keys-revoked-stolen");
  std::filesystem::remove_all(stolen);
  std::filesystem::copy(keys, stolen, std::filesystem::copy_options::recursive);
  (void)SecurityKeyDir(keys).revoke("hostA");

  hapsim::test::BackgroundHapsim serve("serve " + kScene + net_args(session, keys),
                                       fresh_log("secure-revoked-serve"));
  ASSERT_TRUE(serve.wait_for("security     SECURE", std::chrono::seconds(30))) << serve.output();
  // hostB, not revoked, drives the world...
  const hapsim::test::RunResult b =
      hapsim::test::run_hapsim("device --identity hostB --duration 2" + net_args(session, keys));
  EXPECT_EQ(b.exit_code, 0) << b.output;
  ASSERT_TRUE(serve.wait_for("device host  joined", std::chrono::seconds(30))) << serve.output();
  // ...hostA's handshake fails on serve's side (its certificate is on the CRL), so it never sees
  // the served scene.
  const hapsim::test::RunResult a = hapsim::test::run_hapsim(
      "device --identity hostA --duration 3 --session " + session + " --domain " +
      std::to_string(kDomain) + " --secure " + stolen.string());
  EXPECT_EQ(a.exit_code, 2) << a.output;
  EXPECT_NE(a.output.find("no simulation host appeared"), std::string::npos) << a.output;
  EXPECT_TRUE(serve.wait_for("certificate revoked", std::chrono::seconds(30))) << serve.output();
  // With the new keys it is refused before it starts (its identity is gone).
  const hapsim::test::RunResult again =
      hapsim::test::run_hapsim("device --identity hostA --duration 3" + net_args(session, keys));
  EXPECT_EQ(again.exit_code, 2) << again.output;
  EXPECT_NE(again.output.find("no identity 'hostA' here"), std::string::npos) << again.output;
  serve.signal(SIGINT);
  EXPECT_EQ(serve.wait(), 130) << serve.output();
}

// The key directory's checks: each one line naming the file and what is wrong.
std::string refusal(const std::filesystem::path& dir, const std::string& name,
                    const std::string& session) {
  try {
    (void)cyclone_security_xml(dir, name, session);
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

TEST(SecureSessionKeys, RefusesLooseKeysForeignCertificatesMissingFilesAndOtherSessions) {
  const auto keys = fresh_keys("keys-checks", "checks", {"device"});
  EXPECT_EQ(refusal(keys, "serve", "checks"), "");
  EXPECT_NE(cyclone_security_xml(keys, "serve", "checks").find("<CRL>file:"), std::string::npos);

  const std::filesystem::path key = SecurityKeyDir(keys).identity("serve") / "key.pem";
  struct stat st {};
  ASSERT_EQ(::stat(key.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ::chmod(key.c_str(), 0644);
  EXPECT_NE(refusal(keys, "serve", "checks").find(key.string() + ": mode 0644 is looser than 0600"),
            std::string::npos)
      << refusal(keys, "serve", "checks");
  ::chmod(key.c_str(), 0600);

  // A certificate (and key) from another session's CA.
  const auto other = fresh_keys("keys-checks-other", "checks", {"device"});
  const std::filesystem::path cert = SecurityKeyDir(keys).identity("device") / "cert.pem";
  std::filesystem::copy_file(SecurityKeyDir(other).identity("device") / "cert.pem", cert,
                             std::filesystem::copy_options::overwrite_existing);
  const std::string foreign = refusal(keys, "device", "checks");
  EXPECT_NE(foreign.find(cert.string() + ": not accepted by the session CA"), std::string::npos)
      << foreign;

  const std::filesystem::path governance = SecurityKeyDir(keys).governance();
  std::filesystem::copy_file(SecurityKeyDir(other).governance(), governance,
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_NE(refusal(keys, "serve", "checks").find(governance.string() + ": signature"),
            std::string::npos)
      << refusal(keys, "serve", "checks");
  std::filesystem::remove(governance);
  EXPECT_NE(refusal(keys, "serve", "checks").find(governance.string() + ": missing"),
            std::string::npos)
      << refusal(keys, "serve", "checks");

  EXPECT_NE(refusal(keys, "serve", "elsewhere").find("are for session 'checks', not 'elsewhere'"),
            std::string::npos);
  EXPECT_NE(refusal(keys, "nobody", "checks").find("no identity 'nobody' here"), std::string::npos);
  EXPECT_NE(refusal(keys / "nope", "serve", "checks").find("no such key directory"),
            std::string::npos);
}

TEST(SecureSessionKeys, PermissionsGiveEachRoleOnlyItsTopics) {
  const auto keys = fresh_keys("keys-roles", "roles", {"device"});
  const auto permissions = [&](const std::string& name) {
    return read_text_file(SecurityKeyDir(keys).identity(name) / "permissions.xml");
  };
  const auto publish_part = [](const std::string& xml) {
    const std::size_t from = xml.find("<publish>");
    return from == std::string::npos ? std::string()
                                     : xml.substr(from, xml.find("</publish>") - from);
  };
  EXPECT_EQ(publish_part(permissions("viewer")), "");
  EXPECT_NE(publish_part(permissions("device")).find("hapsim_device_state"), std::string::npos);
  EXPECT_EQ(publish_part(permissions("device")).find("hapsim_local_model"), std::string::npos);
  EXPECT_NE(publish_part(permissions("serve")).find("hapsim_local_model"), std::string::npos);
  EXPECT_EQ(publish_part(permissions("serve")).find("hapsim_command<"), std::string::npos);
  EXPECT_NE(publish_part(permissions("instructor")).find("hapsim_command<"), std::string::npos);
  EXPECT_NE(permissions("serve").find("<partition>hapsim.roles</partition>"), std::string::npos);
  // Signed by the permissions CA: the signed text is the document.
  const std::string signed_text =
      smime_verify(read_text_file(SecurityKeyDir(keys).identity("viewer") / "permissions.p7s"),
                   read_text_file(SecurityKeyDir(keys).permissions_ca()), "viewer");
  EXPECT_NE(signed_text.find("<subject_name>CN=viewer,OU=viewer,O=hapsim session roles"),
            std::string::npos)
      << signed_text;
}

}  // namespace
}  // namespace hapsim::net
