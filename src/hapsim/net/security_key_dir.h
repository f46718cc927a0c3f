// A secure session's key directory (`hapsim keys`, docs/security.md): made on one machine, copied
// to the others (all but private/, and each host needs only its own identities/NAME).
//
//   DIR/session                  the session's name (its permissions name partition hapsim.NAME)
//   DIR/identity_ca.pem          the session CA: signs every identity
//   DIR/permissions_ca.pem       the permissions CA: signs governance and permissions
//   DIR/governance.p7s           authentication required, topics encrypted, no unauthenticated
//   DIR/crl.pem                  the session CA's revocation list (hapsim keys revoke)
//   DIR/revoked                  serial and name of each revoked identity
//   DIR/identities/NAME/         cert.pem, key.pem (0600), permissions.p7s, role
//   DIR/private/                 the two CAs' keys (0600): stays on the key machine
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hapsim::net {

/// What an identity may do (SPEC §13): serve publishes models, scenes, views and command replies
/// and reads device states and commands; a device publishes its states and reads models and
/// scenes; a viewer reads scenes and views and publishes nothing; an instructor reads what a
/// viewer reads and the replies, and sends commands.
enum class SecurityRole { kServe, kDevice, kViewer, kInstructor };

[[nodiscard]] std::string_view role_name(SecurityRole role);
[[nodiscard]] std::optional<SecurityRole> parse_role(std::string_view name);

/// The DDS Security 1.1 governance hapsim uses (unsigned text): authentication required,
/// unauthenticated participants refused, join, read and write access control on, every topic's
/// data encrypted and its submessages signed, discovery and liveliness encrypted.
[[nodiscard]] std::string governance_xml();

/// The permissions document of one identity (unsigned text): its role's topics in partition
/// hapsim.SESSION on domains 0-230 (the most DDS Security's documents name), everything else
/// denied.
[[nodiscard]] std::string permissions_xml(const std::string& subject_rfc2253, SecurityRole role,
                                          std::string_view session);

class SecurityKeyDir;

/// The role written beside identity NAME of `keys` (DIR/identities/NAME/role).
[[nodiscard]] std::string read_role(const SecurityKeyDir& keys, std::string_view name);

/// Identity and session names: 1-64 characters of [A-Za-z0-9_.-]. Throws hapsim::Error(where, …).
void check_identity_name(std::string_view name, const std::string& where);

class SecurityKeyDir {
 public:
  explicit SecurityKeyDir(std::filesystem::path dir) : dir_(std::move(dir)) {}

  /// Makes DIR (which must not exist or be empty): both CAs, the governance, an empty revocation
  /// list, and the identities serve, instructor, viewer and one device per name in `devices`.
  static SecurityKeyDir init(const std::filesystem::path& dir, std::string_view session,
                             const std::vector<std::string>& devices);

  /// A new identity NAME with `role` (refused when NAME exists). Needs private/.
  void add(std::string_view name, SecurityRole role) const;
  /// Revokes NAME: its serial goes on the CRL, its files are deleted. Returns the serial.
  std::string revoke(std::string_view name) const;

  [[nodiscard]] std::string session() const;
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] std::filesystem::path identity_ca() const { return dir_ / "identity_ca.pem"; }
  [[nodiscard]] std::filesystem::path permissions_ca() const { return dir_ / "permissions_ca.pem"; }
  [[nodiscard]] std::filesystem::path governance() const { return dir_ / "governance.p7s"; }
  [[nodiscard]] std::filesystem::path crl() const { return dir_ / "crl.pem"; }
  [[nodiscard]] std::filesystem::path identity(std::string_view name) const {
    return dir_ / "identities" / std::string(name);
  }
  /// Names of the identities in DIR, sorted.
  [[nodiscard]] std::vector<std::string> identities() const;

 private:
  std::filesystem::path dir_;
};

}  // namespace hapsim::net
