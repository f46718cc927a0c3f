// The public-key pieces of a secure session (SPEC §13, docs/security.md) through OpenSSL's
// library: EC P-256 keys, X.509 certificates signed by a CA, S/MIME signatures (the DDS Security
// 1.1 governance and permissions documents, signed recordings), a certificate revocation list,
// and the files they live in — a private key is written 0600 and one readable by anyone else is
// refused. Every failure is a hapsim::Error naming the file and what is wrong.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim::net {

/// A private key (PEM, PKCS#8) or a certificate (PEM), held as text: what the files contain.
struct KeyPair {
  std::string key_pem;
  std::string cert_pem;
};

/// The subject of a certificate: O=hapsim session SESSION, OU=ROLE, CN=NAME.
struct Subject {
  std::string session;
  std::string role;
  std::string name;
};

/// A self-signed CA certificate (10 years) for `subject` with a fresh P-256 key.
[[nodiscard]] KeyPair make_ca(const Subject& subject);

/// A fresh key and a certificate for `subject` signed by `ca` (10 years, not a CA).
[[nodiscard]] KeyPair make_identity(const Subject& subject, const KeyPair& ca);

/// The subject as DDS Security's access control compares it (OpenSSL's RFC 2253 form, e.g.
/// "CN=serve,OU=serve,O=hapsim session lab").
[[nodiscard]] std::string subject_name_rfc2253(const std::string& cert_pem);

/// The certificate's serial number in hex (what a revocation list names).
[[nodiscard]] std::string serial_hex(const std::string& cert_pem);

/// The certificate's CN.
[[nodiscard]] std::string common_name(const std::string& cert_pem);

/// Empty when `cert_pem` is signed by `ca_pem`, in date and (with a CRL) not revoked; else why not.
[[nodiscard]] std::string verify_certificate(const std::string& cert_pem, const std::string& ca_pem,
                                             const std::string& crl_pem = {});

/// `text` signed S/MIME by `signer` (PKCS7_DETACHED | PKCS7_TEXT: the clear-signed form DDS
/// Security 1.1 wants for governance and permissions).
[[nodiscard]] std::string smime_sign(const std::string& text, const KeyPair& signer);

/// The signed text of `smime` when its signature holds and its signer's certificate is signed by
/// `ca_pem`; throws hapsim::Error(where, why) otherwise.
[[nodiscard]] std::string smime_verify(const std::string& smime, const std::string& ca_pem,
                                       const std::string& where);

/// As above, and the certificate of the document's signer (PEM) in `signer_cert_pem`, for the
/// caller's own checks of who signed (a signed recording's signer must be a serve identity).
[[nodiscard]] std::string smime_verify(const std::string& smime, const std::string& ca_pem,
                                       const std::string& where, std::string& signer_cert_pem);

/// The certificate's subject: `session` from O ("hapsim session NAME"; empty when O is not of
/// that form), OU as `role`, CN as `name`.
[[nodiscard]] Subject certificate_subject(const std::string& cert_pem);

/// A CRL signed by `ca` listing `revoked_serials_hex` (valid 10 years: Cyclone refuses an
/// expired one).
[[nodiscard]] std::string make_crl(const KeyPair& ca,
                                   const std::vector<std::string>& revoked_serials_hex);

/// Reads a text file; throws hapsim::Error(path, "missing" / "unreadable").
[[nodiscard]] std::string read_text_file(const std::filesystem::path& path);

/// Writes a file (replacing it) with `mode` (0600 for keys, 0644 for the rest).
void write_text_file(const std::filesystem::path& path, std::string_view text, unsigned mode);

/// Throws hapsim::Error(path, "mode 0644 is looser than 0600 …") when group or others may read or
/// write the file, or it is missing.
void require_private_mode(const std::filesystem::path& path);

}  // namespace hapsim::net
