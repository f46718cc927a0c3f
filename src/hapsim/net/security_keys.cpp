#include "hapsim/net/security_keys.h"

#include "hapsim/core/error.h"

#include <fcntl.h>
#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

namespace hapsim::net {

namespace {

template <auto Free>
struct Deleter {
  template <typename T>
  void operator()(T* p) const noexcept {
    Free(p);
  }
};
using Bio = std::unique_ptr<BIO, Deleter<BIO_free_all>>;
using Pkey = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Deleter<X509_free>>;
using Crl = std::unique_ptr<X509_CRL, Deleter<X509_CRL_free>>;
using Pkcs7 = std::unique_ptr<PKCS7, Deleter<PKCS7_free>>;
using Store = std::unique_ptr<X509_STORE, Deleter<X509_STORE_free>>;
using StoreCtx = std::unique_ptr<X509_STORE_CTX, Deleter<X509_STORE_CTX_free>>;
using Bn = std::unique_ptr<BIGNUM, Deleter<BN_free>>;

constexpr long kTenYears_s = 10L * 366 * 24 * 3600;

// OpenSSL's own reason for the last failure, or `fallback`.
std::string ssl_reason(const std::string& fallback) {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) {
    return fallback;
  }
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  return fallback + " (" + text + ")";
}

[[noreturn]] void fail(const std::string& what) {
  throw Error("openssl", ssl_reason(what));
}

Bio memory_bio(std::string_view text) {
  Bio bio(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  if (!bio)
    fail("BIO_new_mem_buf");
  return bio;
}

std::string bio_text(BIO* bio) {
  char* data = nullptr;
  const long size = BIO_get_mem_data(bio, &data);
  return std::string(data, static_cast<std::size_t>(size));
}

Pkey read_key(const std::string& pem) {
  Bio bio = memory_bio(pem);
  Pkey key(PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, nullptr));
  if (!key)
    fail("not a private key");
  return key;
}

Cert read_cert(const std::string& pem) {
  Bio bio = memory_bio(pem);
  Cert cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
  if (!cert)
    fail("not a PEM certificate");
  return cert;
}

std::string key_text(EVP_PKEY* key) {
  Bio out(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_PrivateKey(out.get(), key, nullptr, nullptr, 0, nullptr, nullptr)) {
    fail("writing a key");
  }
  return bio_text(out.get());
}

std::string cert_text(X509* cert) {
  Bio out(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_X509(out.get(), cert))
    fail("writing a certificate");
  return bio_text(out.get());
}

Pkey new_key() {
  Pkey key(EVP_EC_gen("P-256"));
  if (!key)
    fail("generating a P-256 key");
  return key;
}

void set_subject(X509_NAME* name, const Subject& s) {
  const std::string org = "hapsim session " + s.session;
  const auto add = [&](const char* field, const std::string& value) {
    if (!X509_NAME_add_entry_by_txt(name, field, MBSTRING_UTF8,
                                    reinterpret_cast<const unsigned char*>(value.c_str()), -1, -1,
                                    0)) {
      fail(std::string("setting ") + field);
    }
  };
  add("O", org);
  add("OU", s.role);
  add("CN", s.name);
}

void add_extension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (ext == nullptr)
    fail(std::string("extension ") + value);
  const int ok = X509_add_ext(cert, ext, -1);
  X509_EXTENSION_free(ext);
  if (!ok)
    fail(std::string("adding extension ") + value);
}

// A certificate for `key` and `subject`, issued by `issuer` (itself when null) and signed with
// `issuer_key`.
Cert make_cert(EVP_PKEY* key, const Subject& subject, X509* issuer, EVP_PKEY* issuer_key, bool ca) {
  Cert cert(X509_new());
  if (!cert)
    fail("X509_new");
  X509_set_version(cert.get(), 2);
  unsigned char serial[16];
  if (RAND_bytes(serial, sizeof serial) != 1)
    fail("RAND_bytes");
  serial[0] &= 0x7f;  // positive
  Bn bn(BN_bin2bn(serial, sizeof serial, nullptr));
  if (!bn || !BN_to_ASN1_INTEGER(bn.get(), X509_get_serialNumber(cert.get())))
    fail("serial");
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), -3600);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), kTenYears_s);
  X509_set_pubkey(cert.get(), key);
  set_subject(X509_get_subject_name(cert.get()), subject);
  X509* signer = issuer != nullptr ? issuer : cert.get();
  X509_set_issuer_name(cert.get(), X509_get_subject_name(signer));
  if (ca) {
    add_extension(cert.get(), signer, NID_basic_constraints, "critical,CA:TRUE");
    add_extension(cert.get(), signer, NID_key_usage,
                  "critical,keyCertSign,cRLSign,digitalSignature");
  } else {
    add_extension(cert.get(), signer, NID_basic_constraints, "critical,CA:FALSE");
    add_extension(cert.get(), signer, NID_key_usage, "critical,digitalSignature,keyAgreement");
  }
  add_extension(cert.get(), signer, NID_subject_key_identifier, "hash");
  if (X509_sign(cert.get(), issuer_key, EVP_sha256()) == 0)
    fail("signing a certificate");
  return cert;
}

}  // namespace

KeyPair make_ca(const Subject& subject) {
  Pkey key = new_key();
  Cert cert = make_cert(key.get(), subject, nullptr, key.get(), true);
  return {key_text(key.get()), cert_text(cert.get())};
}

KeyPair make_identity(const Subject& subject, const KeyPair& ca) {
  Pkey ca_key = read_key(ca.key_pem);
  Cert ca_cert = read_cert(ca.cert_pem);
  Pkey key = new_key();
  Cert cert = make_cert(key.get(), subject, ca_cert.get(), ca_key.get(), false);
  return {key_text(key.get()), cert_text(cert.get())};
}

std::string subject_name_rfc2253(const std::string& cert_pem) {
  Cert cert = read_cert(cert_pem);
  Bio out(BIO_new(BIO_s_mem()));
  X509_NAME_print_ex(out.get(), X509_get_subject_name(cert.get()), 0, XN_FLAG_RFC2253);
  return bio_text(out.get());
}

std::string serial_hex(const std::string& cert_pem) {
  Cert cert = read_cert(cert_pem);
  Bn bn(ASN1_INTEGER_to_BN(X509_get_serialNumber(cert.get()), nullptr));
  char* hex = BN_bn2hex(bn.get());
  std::string text(hex);
  OPENSSL_free(hex);
  return text;
}

std::string common_name(const std::string& cert_pem) {
  Cert cert = read_cert(cert_pem);
  char text[256] = {};
  X509_NAME_get_text_by_NID(X509_get_subject_name(cert.get()), NID_commonName, text, sizeof text);
  return text;
}

std::string verify_certificate(const std::string& cert_pem, const std::string& ca_pem,
                               const std::string& crl_pem) {
  Cert cert = read_cert(cert_pem);
  Cert ca = read_cert(ca_pem);
  Store store(X509_STORE_new());
  X509_STORE_add_cert(store.get(), ca.get());
  if (!crl_pem.empty()) {
    Bio bio = memory_bio(crl_pem);
    Crl crl(PEM_read_bio_X509_CRL(bio.get(), nullptr, nullptr, nullptr));
    if (!crl)
      return ssl_reason("the revocation list is not a PEM CRL");
    X509_STORE_add_crl(store.get(), crl.get());
    X509_STORE_set_flags(store.get(), X509_V_FLAG_CRL_CHECK);
  }
  StoreCtx ctx(X509_STORE_CTX_new());
  X509_STORE_CTX_init(ctx.get(), store.get(), cert.get(), nullptr);
  if (X509_verify_cert(ctx.get()) == 1) {
    return {};
  }
  const int err = X509_STORE_CTX_get_error(ctx.get());
  ERR_clear_error();
  return X509_verify_cert_error_string(err);
}

std::string smime_sign(const std::string& text, const KeyPair& signer) {
  Pkey key = read_key(signer.key_pem);
  Cert cert = read_cert(signer.cert_pem);
  constexpr int kFlags = PKCS7_DETACHED | PKCS7_TEXT;
  Bio in = memory_bio(text);
  Pkcs7 p7(PKCS7_sign(cert.get(), key.get(), nullptr, in.get(), kFlags));
  if (!p7)
    fail("PKCS7_sign");
  Bio again = memory_bio(text);
  Bio out(BIO_new(BIO_s_mem()));
  if (!SMIME_write_PKCS7(out.get(), p7.get(), again.get(), kFlags))
    fail("SMIME_write_PKCS7");
  return bio_text(out.get());
}

std::string smime_verify(const std::string& smime, const std::string& ca_pem,
                         const std::string& where) {
  std::string signer;
  return smime_verify(smime, ca_pem, where, signer);
}

std::string smime_verify(const std::string& smime, const std::string& ca_pem,
                         const std::string& where, std::string& signer_cert_pem) {
  Bio in = memory_bio(smime);
  BIO* content_raw = nullptr;
  Pkcs7 p7(SMIME_read_PKCS7(in.get(), &content_raw));
  Bio content(content_raw);
  if (!p7)
    throw Error(where, ssl_reason("not an S/MIME signed document"));
  Cert ca = read_cert(ca_pem);
  Store store(X509_STORE_new());
  X509_STORE_add_cert(store.get(), ca.get());
  Bio out(BIO_new(BIO_s_mem()));
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content.get(), out.get(), PKCS7_TEXT) != 1) {
    throw Error(where, ssl_reason("signature does not verify against the session's CA"));
  }
  // The signer PKCS7_verify has just checked (the one certificate PKCS7_sign put in).
  STACK_OF(X509)* signers = PKCS7_get0_signers(p7.get(), nullptr, 0);
  if (signers == nullptr || sk_X509_num(signers) != 1) {
    sk_X509_free(signers);
    throw Error(where, ssl_reason("not signed by exactly one certificate"));
  }
  signer_cert_pem = cert_text(sk_X509_value(signers, 0));
  sk_X509_free(signers);
  return bio_text(out.get());
}

Subject certificate_subject(const std::string& cert_pem) {
  Cert cert = read_cert(cert_pem);
  const auto field = [&](int nid) {
    char text[256] = {};
    X509_NAME_get_text_by_NID(X509_get_subject_name(cert.get()), nid, text, sizeof text);
    return std::string(text);
  };
  const std::string org = field(NID_organizationName);
  const std::string prefix = "hapsim session ";
  Subject s;
  s.session = org.rfind(prefix, 0) == 0 ? org.substr(prefix.size()) : std::string();
  s.role = field(NID_organizationalUnitName);
  s.name = field(NID_commonName);
  return s;
}

std::string make_crl(const KeyPair& ca, const std::vector<std::string>& revoked_serials_hex) {
  Pkey key = read_key(ca.key_pem);
  Cert cert = read_cert(ca.cert_pem);
  Crl crl(X509_CRL_new());
  X509_CRL_set_version(crl.get(), 1);
  X509_CRL_set_issuer_name(crl.get(), X509_get_subject_name(cert.get()));
  using Time = std::unique_ptr<ASN1_TIME, Deleter<ASN1_TIME_free>>;
  Time now(X509_gmtime_adj(nullptr, -3600));
  Time next(X509_gmtime_adj(nullptr, kTenYears_s));
  X509_CRL_set1_lastUpdate(crl.get(), now.get());
  X509_CRL_set1_nextUpdate(crl.get(), next.get());
  for (const std::string& hex : revoked_serials_hex) {
    BIGNUM* raw = nullptr;
    if (BN_hex2bn(&raw, hex.c_str()) == 0)
      throw Error("revoked", "'" + hex + "' is not a serial");
    Bn bn(raw);
    X509_REVOKED* r = X509_REVOKED_new();
    ASN1_INTEGER* serial = BN_to_ASN1_INTEGER(bn.get(), nullptr);
    X509_REVOKED_set_serialNumber(r, serial);
    ASN1_INTEGER_free(serial);
    X509_REVOKED_set_revocationDate(r, now.get());
    X509_CRL_add0_revoked(crl.get(), r);
  }
  X509_CRL_sort(crl.get());
  if (X509_CRL_sign(crl.get(), key.get(), EVP_sha256()) == 0)
    fail("signing the CRL");
  Bio out(BIO_new(BIO_s_mem()));
  PEM_write_bio_X509_CRL(out.get(), crl.get());
  return bio_text(out.get());
}

std::string read_text_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(path.string(), "missing (run hapsim keys init, or copy it from the key machine)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(path.string(), "cannot be read");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text_file(const std::filesystem::path& path, std::string_view text, unsigned mode) {
  const std::filesystem::path temp = path.string() + ".new";
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode);
  if (fd < 0)
    throw Error(temp.string(), std::strerror(errno));
  bool ok = ::fchmod(fd, mode) == 0;
  std::size_t done = 0;
  while (ok && done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    ok = n > 0;
    done += ok ? static_cast<std::size_t>(n) : 0;
  }
  ok = ::close(fd) == 0 && ok;
  if (!ok || std::rename(temp.c_str(), path.c_str()) != 0) {
    throw Error(path.string(), std::string("cannot be written: ") + std::strerror(errno));
  }
}

void require_private_mode(const std::filesystem::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw Error(path.string(), "missing (a private key; run hapsim keys init or add-*)");
  }
  const unsigned mode = st.st_mode & 07777U;
  if ((mode & 077U) != 0) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "mode %04o is looser than 0600: a private key must be readable by its owner only "
                  "(chmod 600 it)",
                  mode);
    throw Error(path.string(), text);
  }
}

}  // namespace hapsim::net
