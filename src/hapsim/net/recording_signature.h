// Signed recordings (issue 32, docs/security.md#signed-recordings): a secure serve that records
// (`hapsim serve --secure DIR --record FILE`) writes FILE.sig beside the finished recording, a
// statement of what it recorded — the file's SHA-256 and length, the scene's hash, the session,
// the signer, the time and how many cycles a device host drove — S/MIME-signed with the serve
// identity's key (smime_sign, security_keys.h). `hapsim assess --verify` checks it before it
// scores anything: the signature holds against the session's identity CA, the signer is not on
// its revocation list and has the serve role, and the file is the one signed, byte for byte. A
// recording made without a secure serve (`hapsim run --record`, a script) has no such signature.
#pragma once

#include "hapsim/net/security_key_dir.h"
#include "hapsim/net/security_keys.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace hapsim::net {

/// Where a recording's signature lies: FILE.sig.
[[nodiscard]] std::filesystem::path recording_signature_path(
    const std::filesystem::path& recording);

/// Longest signature file read (a statement and one certificate are about 3 KB).
inline constexpr std::uintmax_t kMaxRecordingSignatureBytes = 64 * 1024;

/// What a signature says of its recording (the signed text, docs/recording-format.md).
struct RecordingStatement {
  std::string recording;  ///< the file's name when it was signed (printable; informative only)
  std::uint64_t bytes = 0;
  std::string sha256_hex;      ///< 64 lowercase hex digits, of the whole file
  std::string scene_hash_hex;  ///< net::scene_hash of the header's content hash, 16 hex digits
  std::string session;
  std::string identity;   ///< the signer's name (its certificate's CN)
  std::string signed_at;  ///< UTC, ISO 8601 (2026-11-29T03:04:05Z)
  std::uint64_t cycles = 0;
  std::uint64_t device_host_cycles = 0;  ///< cycles a device host's states drove the world
};

/// The signed text: a first line "hapsim recording signature 1", then one "key: value" per field.
[[nodiscard]] std::string recording_statement_text(const RecordingStatement& statement);
/// Parses that text; throws hapsim::Error(where, …) naming a missing or malformed field.
[[nodiscard]] RecordingStatement parse_recording_statement(std::string_view text,
                                                           const std::string& where);

struct FileDigest {
  std::string sha256_hex;
  std::uint64_t bytes = 0;
};
/// The SHA-256 (OpenSSL EVP) and length of a file, read in blocks. Throws hapsim::Error(path, …).
[[nodiscard]] FileDigest sha256_file(const std::filesystem::path& path);

/// Signs recordings as one identity of a key directory.
class RecordingSigner {
 public:
  /// Identity `identity` of `keys`: its key (0600) and certificate are read and checked against
  /// the session's CA and revocation list now, so a bad key fails before a session runs.
  /// Throws hapsim::Error naming the file.
  RecordingSigner(const SecurityKeyDir& keys, std::string_view identity);

  /// Writes recording_signature_path(recording) for the file as it is now (finished), with
  /// `cycles` and `device_host_cycles`; returns the statement. Throws hapsim::Error.
  RecordingStatement sign(const std::filesystem::path& recording, std::uint64_t cycles,
                          std::uint64_t device_host_cycles) const;

 private:
  KeyPair signer_;
  std::string session_;
  std::string identity_;
};

/// Checks `recording` against its FILE.sig and the key directory `keys` (its identity_ca.pem,
/// crl.pem and session): the signature file is there, its S/MIME signature holds against the
/// session's identity CA, the signer's certificate is not revoked and has role serve and this
/// session, and the file's length, SHA-256 and scene hash are the statement's. Returns the
/// statement; throws hapsim::Error(recording, reason) on the first check that fails.
[[nodiscard]] RecordingStatement verify_recording_signature(const std::filesystem::path& recording,
                                                            const SecurityKeyDir& keys);

}  // namespace hapsim::net
