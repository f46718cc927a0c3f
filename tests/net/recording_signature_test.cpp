// Signed recordings (issue 32, docs/security.md#signed-recordings): a recording signed by a serve
// identity verifies against its session's keys, and each way it can be wrong is refused with a
// reason naming the file — a byte altered, the file cut short, no signature, the statement
// edited, a device's or viewer's signature, a revoked serve, another session's CA.
#include "hapsim/net/recording_signature.h"
#include "hapsim/core/error.h"
#include "hapsim/device/recording.h"
#include "hapsim/net/scene_hash.h"
#include "hapsim/net/security_key_dir.h"
#include "hapsim/net/security_keys.h"

#include "apps/hapsim_process.h"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

namespace hapsim::net {
namespace {

namespace fs = std::filesystem;

constexpr const char* kContentHash = "toy-scene-content";

fs::path fresh_keys(const std::string& name, const std::string& session) {
  const fs::path dir = hapsim::test::temp_path(name);
  fs::remove_all(dir);
  (void)SecurityKeyDir::init(dir, session, {"rig1"});
  return dir;
}

// A recording of `frames` cycles of a toy scene, as a session writes one.
fs::path make_recording(const std::string& name, std::size_t frames) {
  const fs::path path = hapsim::test::temp_path(name);
  SessionRecorder recorder(path, kContentHash, 64, SessionRecorder::Overflow::kFlushInline);
  for (std::size_t i = 0; i < frames; ++i) {
    RecordedFrame f;
    f.cycle_index = i;
    f.input.time_s = 0.001 * static_cast<double>(i);
    f.input.p_world = Vec3(0.0, 0.0, 0.05 - 1e-5 * static_cast<double>(i));
    f.command.force_world_n = Vec3(0.0, 0.0, 0.01 * static_cast<double>(i % 50));
    recorder.record(f);
  }
  recorder.close();
  return path;
}

std::string contents(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_contents(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
}

// Why verification refused `recording` ("" when it verified).
std::string refusal(const fs::path& recording, const fs::path& keys) {
  try {
    (void)verify_recording_signature(recording, SecurityKeyDir(keys));
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), recording.string());  // every refusal names the recording
    return e.what();
  }
  return {};
}

TEST(RecordingSignature, ASignedRecordingVerifiesAndSaysWhatWasSigned) {
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path rec = make_recording("signed.rec", 450);
  const RecordingStatement signed_as =
      RecordingSigner(SecurityKeyDir(keys), "serve").sign(rec, 450, 120);
  EXPECT_TRUE(fs::is_regular_file(rec.string() + ".sig"));
  EXPECT_EQ(recording_signature_path(rec), fs::path(rec.string() + ".sig"));

  const RecordingStatement s = verify_recording_signature(rec, SecurityKeyDir(keys));
  EXPECT_EQ(s.bytes, fs::file_size(rec));
  EXPECT_EQ(s.sha256_hex, sha256_file(rec).sha256_hex);
  EXPECT_EQ(s.sha256_hex, signed_as.sha256_hex);
  EXPECT_EQ(s.session, "lab");
  EXPECT_EQ(s.identity, "serve");
  EXPECT_EQ(s.cycles, 450u);
  EXPECT_EQ(s.device_host_cycles, 120u);
  EXPECT_EQ(s.recording, rec.filename().string());
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016" PRIx64, scene_hash(kContentHash));
  EXPECT_EQ(s.scene_hash_hex, hash);
  EXPECT_EQ(s.signed_at.size(), 20u) << s.signed_at;  // 2026-11-29T03:04:05Z
}

TEST(RecordingSignature, Sha256IsTheStandardDigest) {
  // FIPS 180-2's "abc" example.
  const fs::path p = hapsim::test::temp_path("abc.txt");
  write_contents(p, "abc");
  const FileDigest d = sha256_file(p);
  EXPECT_EQ(d.bytes, 3u);
  EXPECT_EQ(d.sha256_hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(RecordingSignature, OneByteAlteredIsRefused) {
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path rec = make_recording("altered.rec", 300);
  (void)RecordingSigner(SecurityKeyDir(keys), "serve").sign(rec, 300, 0);
  std::string bytes = contents(rec);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x01);
  write_contents(rec, bytes);
  EXPECT_NE(refusal(rec, keys).find("digest does not match"), std::string::npos)
      << refusal(rec, keys);
}

TEST(RecordingSignature, ATruncatedOrExtendedRecordingIsRefused) {
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path rec = make_recording("cut.rec", 300);
  (void)RecordingSigner(SecurityKeyDir(keys), "serve").sign(rec, 300, 0);
  const std::string bytes = contents(rec);
  write_contents(rec, bytes.substr(0, bytes.size() - 100));
  EXPECT_NE(refusal(rec, keys).find("bytes, its signature says " + std::to_string(bytes.size())),
            std::string::npos)
      << refusal(rec, keys);
  write_contents(rec, bytes + "x");
  EXPECT_NE(refusal(rec, keys).find("cut short or added to"), std::string::npos)
      << refusal(rec, keys);
  write_contents(rec, bytes);
  EXPECT_EQ(refusal(rec, keys), "");
}

TEST(RecordingSignature, AnUnsignedOrMissingRecordingIsRefused) {
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path rec = make_recording("unsigned.rec", 10);
  EXPECT_NE(refusal(rec, keys).find("not signed: " + rec.string() + ".sig is not there"),
            std::string::npos)
      << refusal(rec, keys);
  const fs::path nowhere = hapsim::test::temp_path("nowhere.rec");
  EXPECT_NE(refusal(nowhere, keys).find("no such recording"), std::string::npos);
}

TEST(RecordingSignature, AnEditedStatementOrAForeignSignatureFileIsRefused) {
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path rec = make_recording("edited.rec", 200);
  (void)RecordingSigner(SecurityKeyDir(keys), "serve").sign(rec, 200, 0);
  const fs::path sig = recording_signature_path(rec);
  const std::string signed_text = contents(sig);
  // Claiming a device host drove the session: the clear text no longer matches the signature.
  std::string edited = signed_text;
  const std::size_t at = edited.find("device_host_cycles: 0");
  ASSERT_NE(at, std::string::npos) << edited;
  edited.replace(at, 21, "device_host_cycles: 9");
  write_contents(sig, edited);
  EXPECT_NE(refusal(rec, keys).find("does not verify against the session CA"), std::string::npos)
      << refusal(rec, keys);
  write_contents(sig, "not a signature\n");
  EXPECT_NE(refusal(rec, keys).find("does not verify against the session CA"), std::string::npos)
      << refusal(rec, keys);
  write_contents(sig, std::string(kMaxRecordingSignatureBytes + 1, 'x'));
  EXPECT_NE(refusal(rec, keys).find("not a recording signature"), std::string::npos)
      << refusal(rec, keys);
  // Another recording's signature (a valid one) does not fit this file.
  const fs::path other = make_recording("other.rec", 201);
  (void)RecordingSigner(SecurityKeyDir(keys), "serve").sign(other, 201, 0);
  fs::copy_file(recording_signature_path(other), sig, fs::copy_options::overwrite_existing);
  EXPECT_FALSE(refusal(rec, keys).empty());
  write_contents(sig, signed_text);
  EXPECT_EQ(refusal(rec, keys), "");
}

TEST(RecordingSignature, OnlyAServeIdentitysSignatureCounts) {
  const fs::path keys = fresh_keys("keys", "lab");
  for (const char* identity : {"rig1", "viewer", "instructor"}) {
    const fs::path rec = make_recording(std::string(identity) + ".rec", 50);
    (void)RecordingSigner(SecurityKeyDir(keys), identity).sign(rec, 50, 50);
    const std::string why = refusal(rec, keys);
    EXPECT_NE(why.find(std::string("signed by '") + identity + "' of role '"), std::string::npos)
        << why;
    EXPECT_NE(why.find("not a serve identity"), std::string::npos) << why;
  }
}

TEST(RecordingSignature, ARevokedServesSignatureIsRefused) {
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path rec = make_recording("revoked.rec", 50);
  (void)RecordingSigner(SecurityKeyDir(keys), "serve").sign(rec, 50, 0);
  ASSERT_EQ(refusal(rec, keys), "");
  (void)SecurityKeyDir(keys).revoke("serve");
  const std::string why = refusal(rec, keys);
  EXPECT_NE(why.find("whose certificate the session CA does not accept: certificate revoked"),
            std::string::npos)
      << why;
}

TEST(RecordingSignature, AnotherSessionsSignatureIsRefused) {
  // The same session name, keys made twice: another CA.
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path other = fresh_keys("keys-other", "lab");
  const fs::path rec = make_recording("foreign.rec", 50);
  (void)RecordingSigner(SecurityKeyDir(other), "serve").sign(rec, 50, 0);
  EXPECT_EQ(refusal(rec, other), "");
  const std::string why = refusal(rec, keys);
  EXPECT_NE(why.find("does not verify against the session CA " +
                     SecurityKeyDir(keys).identity_ca().string()),
            std::string::npos)
      << why;
}

TEST(RecordingSignature, ASignerWithABadKeyFailsBeforeASession) {
  const fs::path keys = fresh_keys("keys", "lab");
  const fs::path key = SecurityKeyDir(keys).identity("serve") / "key.pem";
  // Another identity's key beside serve's certificate: it cannot sign as serve.
  fs::copy_file(SecurityKeyDir(keys).identity("viewer") / "key.pem", key,
                fs::copy_options::overwrite_existing);
  EXPECT_THROW(RecordingSigner(SecurityKeyDir(keys), "serve"), Error);
  EXPECT_THROW(RecordingSigner(SecurityKeyDir(keys), "nobody"), Error);
}

TEST(RecordingSignature, TheStatementParsesBackAndRefusesMalformedText) {
  RecordingStatement s;
  s.recording = "a\nb.rec";  // a control character in a name is escaped, not a new line
  s.bytes = 123;
  s.sha256_hex = std::string(64, 'a');
  s.scene_hash_hex = "0123456789abcdef";
  s.session = "lab";
  s.identity = "serve";
  s.signed_at = "2026-11-29T03:04:05Z";
  s.cycles = 7;
  s.device_host_cycles = 5;
  const RecordingStatement back = parse_recording_statement(recording_statement_text(s), "t");
  EXPECT_EQ(back.recording, "a\\x0ab.rec");
  EXPECT_EQ(back.bytes, 123u);
  EXPECT_EQ(back.sha256_hex, s.sha256_hex);
  EXPECT_EQ(back.device_host_cycles, 5u);
  EXPECT_THROW((void)parse_recording_statement("something else\n", "t"), Error);
  EXPECT_THROW((void)parse_recording_statement("", "t"), Error);
  std::string no_bytes = recording_statement_text(s);
  no_bytes.replace(no_bytes.find("bytes: 123"), 10, "bytes: 12x");
  EXPECT_THROW((void)parse_recording_statement(no_bytes, "t"), Error);
}

}  // namespace
}  // namespace hapsim::net
