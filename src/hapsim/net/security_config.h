// The Cyclone DDS security configuration of one process in a secure session (`--secure DIR`,
// docs/security.md): DIR checked first — the session's name, the identity's key private (0600),
// its certificate signed by the session CA and not revoked, governance and permissions signed by
// the permissions CA — then a <Security> fragment naming the builtin plugins (PKI-DH
// authentication, access control, AES-GCM) and DIR's files, which DdsDomain appends to the rest of
// the configuration.
#pragma once

#include "hapsim/net/security_key_dir.h"

#include <filesystem>
#include <string>
#include <string_view>

namespace hapsim::net {

/// The identity a command uses unless told (`--identity`): serve → "serve", a viewer → "viewer",
/// control → "instructor", a device host → this machine's host name when DIR has that identity,
/// else "device".
[[nodiscard]] std::string default_identity(SecurityRole role, const std::filesystem::path& dir);

/// The checked <CycloneDDS><Domain><Security> fragment for identity `name` of DIR in `session`.
/// Throws hapsim::Error naming the file and what is wrong.
[[nodiscard]] std::string cyclone_security_xml(const std::filesystem::path& dir,
                                               std::string_view name, std::string_view session);

/// Where Cyclone's builtin security plugins are (libdds_security_auth.so and the others): next to
/// libddsc in libddsc0debian/ (Debian's package), or next to libddsc itself.
[[nodiscard]] std::filesystem::path dds_security_library_dir();

}  // namespace hapsim::net
