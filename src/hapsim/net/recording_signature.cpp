#include "hapsim/net/recording_signature.h"

#include "hapsim/core/error.h"
#include "hapsim/core/printable_text.h"
#include "hapsim/device/recording.h"
#include "hapsim/net/scene_hash.h"

#include <openssl/evp.h>

#include <array>
#include <charconv>
#include <cinttypes>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <system_error>

namespace hapsim::net {

namespace {

constexpr std::string_view kFirstLine = "hapsim recording signature 1";

std::string hex_of(const unsigned char* bytes, std::size_t n) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string text;
  for (std::size_t i = 0; i < n; ++i) {
    text += kDigits[bytes[i] >> 4U];
    text += kDigits[bytes[i] & 0xfU];
  }
  return text;
}

bool is_hex(std::string_view text, std::size_t length) {
  return text.size() == length && text.find_first_not_of("0123456789abcdef") == std::string::npos;
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

// The scene hash a recording's header holds, as serve prints it.
std::string header_scene_hash(const std::filesystem::path& recording) {
  const RecordingReader reader(recording, RecordingReader::TornEnd::kQuiet);
  char text[17];
  std::snprintf(text, sizeof text, "%016" PRIx64, scene_hash(reader.header().scene_hash));
  return text;
}

}  // namespace

std::filesystem::path recording_signature_path(const std::filesystem::path& recording) {
  return recording.string() + ".sig";
}

std::string recording_statement_text(const RecordingStatement& s) {
  std::string text(kFirstLine);
  text += "\nrecording: " + printable_text(s.recording) + "\nbytes: " + std::to_string(s.bytes) +
          "\nsha256: " + s.sha256_hex + "\nscene_hash: " + s.scene_hash_hex +
          "\nsession: " + s.session + "\nidentity: " + s.identity + "\nsigned_at: " + s.signed_at +
          "\ncycles: " + std::to_string(s.cycles) +
          "\ndevice_host_cycles: " + std::to_string(s.device_host_cycles) + "\n";
  return text;
}

RecordingStatement parse_recording_statement(std::string_view text, const std::string& where) {
  std::map<std::string, std::string, std::less<>> fields;
  bool first = true;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    if (!line.empty() && line.back() == '\r') {
      line.remove_suffix(1);  // S/MIME's canonical text ends lines CRLF
    }
    if (first) {
      if (line != kFirstLine) {
        throw Error(where,
                    "the signed text is not a hapsim recording statement (its first line "
                    "is '" +
                        printable_text(line, 80) + "')");
      }
      first = false;
      continue;
    }
    if (line.empty()) {
      continue;
    }
    const std::size_t colon = line.find(": ");
    if (colon == std::string_view::npos) {
      throw Error(where,
                  "the statement's line '" + printable_text(line, 80) + "' is not 'key: value'");
    }
    fields[std::string(line.substr(0, colon))] = std::string(line.substr(colon + 2));
  }
  if (first) {
    throw Error(where, "the signed text is empty");
  }
  const auto field = [&](const char* key) -> const std::string& {
    const auto it = fields.find(key);
    if (it == fields.end()) {
      throw Error(where, std::string("the statement has no '") + key + "'");
    }
    return it->second;
  };
  const auto number = [&](const char* key) {
    const std::string& value = field(key);
    std::uint64_t n = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
    if (ec != std::errc() || end != value.data() + value.size() || value.empty()) {
      throw Error(where, std::string("the statement's '") + key + "' is not a count: '" +
                             printable_text(value, 40) + "'");
    }
    return n;
  };
  RecordingStatement s;
  s.recording = field("recording");
  s.bytes = number("bytes");
  s.sha256_hex = field("sha256");
  s.scene_hash_hex = field("scene_hash");
  s.session = field("session");
  s.identity = field("identity");
  s.signed_at = field("signed_at");
  s.cycles = number("cycles");
  s.device_host_cycles = number("device_host_cycles");
  if (!is_hex(s.sha256_hex, 64)) {
    throw Error(where, "the statement's sha256 is not 64 hex digits");
  }
  if (!is_hex(s.scene_hash_hex, 16)) {
    throw Error(where, "the statement's scene_hash is not 16 hex digits");
  }
  return s;
}

FileDigest sha256_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw Error(path.string(), "cannot be read");
  }
  const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(),
                                                                    &EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) {
    throw Error(path.string(), "OpenSSL could not start a SHA-256");
  }
  FileDigest digest;
  std::array<char, 1 << 16> block{};
  while (in) {
    in.read(block.data(), block.size());
    const std::streamsize n = in.gcount();
    if (n > 0) {
      EVP_DigestUpdate(ctx.get(), block.data(), static_cast<std::size_t>(n));
      digest.bytes += static_cast<std::uint64_t>(n);
    }
  }
  if (in.bad()) {
    throw Error(path.string(), "a read failed");
  }
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(ctx.get(), md.data(), &length) != 1) {
    throw Error(path.string(), "OpenSSL could not finish the SHA-256");
  }
  digest.sha256_hex = hex_of(md.data(), length);
  return digest;
}

RecordingSigner::RecordingSigner(const SecurityKeyDir& keys, std::string_view identity)
    : session_(keys.session()), identity_(identity) {
  check_identity_name(identity, "--identity");
  const std::filesystem::path me = keys.identity(identity);
  require_private_mode(me / "key.pem");
  signer_.key_pem = read_text_file(me / "key.pem");
  signer_.cert_pem = read_text_file(me / "cert.pem");
  const std::string why = verify_certificate(signer_.cert_pem, read_text_file(keys.identity_ca()),
                                             read_text_file(keys.crl()));
  if (!why.empty()) {
    throw Error((me / "cert.pem").string(), "not accepted by the session CA: " + why);
  }
  // A key that does not sign (or is not the certificate's) fails here, not after a session.
  (void)smime_verify(smime_sign("probe", signer_), read_text_file(keys.identity_ca()),
                     (me / "key.pem").string());
}

RecordingStatement RecordingSigner::sign(const std::filesystem::path& recording,
                                         std::uint64_t cycles,
                                         std::uint64_t device_host_cycles) const {
  RecordingStatement s;
  s.recording = recording.filename().string();
  const FileDigest digest = sha256_file(recording);
  s.bytes = digest.bytes;
  s.sha256_hex = digest.sha256_hex;
  s.scene_hash_hex = header_scene_hash(recording);
  s.session = session_;
  s.identity = identity_;
  s.signed_at = utc_now();
  s.cycles = cycles;
  s.device_host_cycles = device_host_cycles;
  write_text_file(recording_signature_path(recording),
                  smime_sign(recording_statement_text(s), signer_), 0644);
  return s;
}

RecordingStatement verify_recording_signature(const std::filesystem::path& recording,
                                              const SecurityKeyDir& keys) {
  const std::string where = recording.string();
  const std::filesystem::path sig = recording_signature_path(recording);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(recording, ec)) {
    throw Error(where, "no such recording");
  }
  if (!std::filesystem::is_regular_file(sig, ec)) {
    throw Error(where, "not signed: " + sig.string() +
                           " is not there (a secure serve writes it: hapsim serve --secure DIR "
                           "--record FILE)");
  }
  if (const std::uintmax_t size = std::filesystem::file_size(sig, ec);
      ec || size > kMaxRecordingSignatureBytes) {
    throw Error(where, sig.string() + " is " +
                           (ec ? "unreadable" : std::to_string(size) + " bytes") +
                           ": not a recording signature");
  }
  const std::filesystem::path ca_file = keys.identity_ca();
  const std::string ca = read_text_file(ca_file);
  std::string signer_cert;
  std::string text;
  try {
    text = smime_verify(read_text_file(sig), ca, sig.string(), signer_cert);
  } catch (const Error& e) {
    throw Error(where, "its signature " + sig.string() +
                           " does not verify against the session CA " + ca_file.string() + ": " +
                           e.detail());
  }
  const Subject signer = certificate_subject(signer_cert);
  std::string named = printable_text(signer.name, 64);
  named.insert(named.begin(), '\'');
  named += '\'';
  if (const std::string why = verify_certificate(signer_cert, ca, read_text_file(keys.crl()));
      !why.empty()) {
    throw Error(where, "signed by " + named +
                           ", whose certificate the session CA does not accept: " + why + " (" +
                           keys.crl().string() + ")");
  }
  if (signer.role != role_name(SecurityRole::kServe)) {
    throw Error(where, "signed by " + named + " of role '" + printable_text(signer.role, 32) +
                           "', not a serve identity (only serve signs recordings)");
  }
  const std::string session = keys.session();
  if (signer.session != session) {
    throw Error(where, "signed by " + named + " of session '" + printable_text(signer.session, 64) +
                           "', not " + session);
  }
  const RecordingStatement s = parse_recording_statement(text, sig.string());
  if (s.identity != signer.name || s.session != signer.session) {
    throw Error(where, "its statement names identity '" + printable_text(s.identity, 64) +
                           "' of session '" + printable_text(s.session, 64) + "' but " + named +
                           " of session '" + signer.session + "' signed it");
  }
  const FileDigest digest = sha256_file(recording);
  if (digest.bytes != s.bytes) {
    throw Error(where, "the recording is " + std::to_string(digest.bytes) +
                           " bytes, its signature says " + std::to_string(s.bytes) +
                           " (cut short or added to since it was signed)");
  }
  if (digest.sha256_hex != s.sha256_hex) {
    throw Error(where,
                "its SHA-256 digest does not match the signature's (the recording was "
                "altered since it was signed)");
  }
  std::string scene;
  try {
    scene = header_scene_hash(recording);
  } catch (const Error& e) {
    throw Error(where, std::string("signed, but its header does not read: ") + e.detail());
  }
  if (scene != s.scene_hash_hex) {
    throw Error(where,
                "its header's scene hash " + scene + " is not the signed " + s.scene_hash_hex);
  }
  return s;
}

}  // namespace hapsim::net
