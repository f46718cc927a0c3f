#include "hapsim/net/security_config.h"

#include "hapsim/core/error.h"
#include "hapsim/net/security_keys.h"

#include <dds/dds.h>
#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <system_error>

namespace hapsim::net {

namespace {

// Paths go into XML and into Cyclone's comma-separated config list.
std::string xml_path(const std::filesystem::path& path) {
  const std::string text = std::filesystem::absolute(path).lexically_normal().string();
  if (std::any_of(text.begin(), text.end(), [](char c) {
        return c == '<' || c == '>' || c == '&' || c == '"' || c == '\'' || c == ',';
      })) {
    throw Error(text, "a secure session's path may not contain < > & \" ' or ,");
  }
  return text;
}

std::string file_uri(const std::filesystem::path& path) {
  return "file:" + xml_path(path);
}

std::string library(const std::filesystem::path& dir, const char* name, const char* init,
                    const char* finalize) {
  return std::string("<Library path=\"") + xml_path(dir / name) + "\" initFunction=\"" + init +
         "\" finalizeFunction=\"" + finalize + "\"/>";
}

}  // namespace

std::string default_identity(SecurityRole role, const std::filesystem::path& dir) {
  switch (role) {
    case SecurityRole::kServe:
      return "serve";
    case SecurityRole::kViewer:
      return "viewer";
    case SecurityRole::kInstructor:
      return "instructor";
    case SecurityRole::kDevice:
      break;
  }
  char host[256] = {};
  std::error_code ec;
  if (::gethostname(host, sizeof host - 1) == 0 && host[0] != '\0' &&
      std::filesystem::is_directory(SecurityKeyDir(dir).identity(host), ec)) {
    return host;
  }
  return "device";
}

std::filesystem::path dds_security_library_dir() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&dds_create_participant), &info) != 0 &&
      info.dli_fname != nullptr) {
    const std::filesystem::path libdir = std::filesystem::canonical(info.dli_fname).parent_path();
    std::error_code ec;
    for (const std::filesystem::path& dir : {libdir / "libddsc0debian", libdir}) {
      if (std::filesystem::exists(dir / "libdds_security_auth.so", ec))
        return dir;
    }
  }
  throw Error("libdds_security_auth.so",
              "Cyclone DDS's security plugins are not installed next to libddsc (Debian: "
              "libddsc0debian)");
}

std::string cyclone_security_xml(const std::filesystem::path& dir, std::string_view name,
                                 std::string_view session) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    throw Error(dir.string(),
                "no such key directory (make one with hapsim keys init DIR --session "
                "NAME on the key machine and copy it here)");
  }
  const SecurityKeyDir keys(dir);
  check_identity_name(name, "--identity");
  const std::string dir_session = keys.session();
  if (dir_session != session) {
    throw Error((dir / "session").string(), "these keys are for session '" + dir_session +
                                                "', not '" + std::string(session) +
                                                "' (give --session " + dir_session + ")");
  }
  const std::filesystem::path me = keys.identity(name);
  if (!std::filesystem::is_directory(me, ec)) {
    std::string known;
    for (const std::string& n : keys.identities())
      known += (known.empty() ? "" : ", ") + n;
    throw Error(me.string(), "no identity '" + std::string(name) +
                                 "' here (identities: " + (known.empty() ? "none" : known) +
                                 "; hapsim keys add-device/add-viewer NAME makes one)");
  }
  require_private_mode(me / "key.pem");
  const std::string ca = read_text_file(keys.identity_ca());
  const std::string cert = read_text_file(me / "cert.pem");
  const std::string crl = read_text_file(keys.crl());
  const std::string why = verify_certificate(cert, ca, crl);
  if (!why.empty()) {
    throw Error((me / "cert.pem").string(),
                "not accepted by the session CA " + keys.identity_ca().string() + ": " + why);
  }
  const std::string perm_ca = read_text_file(keys.permissions_ca());
  (void)smime_verify(read_text_file(keys.governance()), perm_ca, keys.governance().string());
  (void)smime_verify(read_text_file(me / "permissions.p7s"), perm_ca,
                     (me / "permissions.p7s").string());
  const std::filesystem::path libs = dds_security_library_dir();
  return "<CycloneDDS><Domain id=\"any\"><Security><Authentication>" +
         library(libs, "libdds_security_auth.so", "init_authentication",
                 "finalize_authentication") +
         "<IdentityCA>" + file_uri(keys.identity_ca()) + "</IdentityCA><IdentityCertificate>" +
         file_uri(me / "cert.pem") + "</IdentityCertificate><PrivateKey>" +
         file_uri(me / "key.pem") + "</PrivateKey><CRL>" + file_uri(keys.crl()) +
         "</CRL></Authentication><AccessControl>" +
         library(libs, "libdds_security_ac.so", "init_access_control", "finalize_access_control") +
         "<PermissionsCA>" + file_uri(keys.permissions_ca()) + "</PermissionsCA><Governance>" +
         file_uri(keys.governance()) + "</Governance><Permissions>" +
         file_uri(me / "permissions.p7s") + "</Permissions></AccessControl><Cryptographic>" +
         library(libs, "libdds_security_crypto.so", "init_crypto", "finalize_crypto") +
         "</Cryptographic></Security></Domain></CycloneDDS>";
}

}  // namespace hapsim::net
