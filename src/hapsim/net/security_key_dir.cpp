#include "hapsim/net/security_key_dir.h"

#include "hapsim/core/error.h"
#include "hapsim/net/participant.h"
#include "hapsim/net/security_keys.h"
#include "hapsim/net/topics.h"

#include <sys/stat.h>

#include <algorithm>
#include <ctime>
#include <sstream>
#include <system_error>

namespace hapsim::net {

namespace {

constexpr unsigned kPrivate = 0600;
constexpr unsigned kPublic = 0644;

struct RoleTopics {
  std::vector<const char*> publish;
  std::vector<const char*> subscribe;
};

template <typename T>
constexpr const char* topic() {
  return TopicTraits<T>::kName;
}

RoleTopics role_topics(SecurityRole role) {
  switch (role) {
    case SecurityRole::kServe:
      return {{topic<hapsim_msg_LocalModel>(), topic<hapsim_msg_SceneInfo>(),
               topic<hapsim_msg_ViewState>(), topic<hapsim_msg_CommandReply>()},
              {topic<hapsim_msg_DeviceState>(), topic<hapsim_msg_Command>()}};
    case SecurityRole::kDevice:
      return {{topic<hapsim_msg_DeviceState>()},
              {topic<hapsim_msg_LocalModel>(), topic<hapsim_msg_SceneInfo>()}};
    case SecurityRole::kViewer:
      return {{}, {topic<hapsim_msg_SceneInfo>(), topic<hapsim_msg_ViewState>()}};
    case SecurityRole::kInstructor:
      return {{topic<hapsim_msg_Command>()},
              {topic<hapsim_msg_SceneInfo>(), topic<hapsim_msg_ViewState>(),
               topic<hapsim_msg_CommandReply>()}};
  }
  return {};
}

std::string xml_date(std::time_t t) {
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

std::string criteria(const char* element, const std::vector<const char*>& topics,
                     const std::string& partition) {
  if (topics.empty()) {
    return {};
  }
  std::string xml = std::string("        <") + element + ">\n          <topics>\n";
  for (const char* t : topics) {
    xml += std::string("            <topic>") + t + "</topic>\n";
  }
  xml += "          </topics>\n          <partitions>\n            <partition>" + partition +
         "</partition>\n          </partitions>\n        </" + element + ">\n";
  return xml;
}

KeyPair read_pair(const std::filesystem::path& key, const std::filesystem::path& cert) {
  require_private_mode(key);
  return {read_text_file(key), read_text_file(cert)};
}

void make_private_dir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw Error(dir.string(), "cannot be made: " + ec.message());
  ::chmod(dir.c_str(), 0700);
}

std::string trim(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ' || text.back() == '\r')) {
    text.pop_back();
  }
  return text;
}

}  // namespace

std::string_view role_name(SecurityRole role) {
  switch (role) {
    case SecurityRole::kServe:
      return "serve";
    case SecurityRole::kDevice:
      return "device";
    case SecurityRole::kViewer:
      return "viewer";
    case SecurityRole::kInstructor:
      return "instructor";
  }
  return "?";
}

std::optional<SecurityRole> parse_role(std::string_view name) {
  for (SecurityRole r : {SecurityRole::kServe, SecurityRole::kDevice, SecurityRole::kViewer,
                         SecurityRole::kInstructor}) {
    if (role_name(r) == name)
      return r;
  }
  return std::nullopt;
}

void check_identity_name(std::string_view name, const std::string& where) {
  const bool ok = !name.empty() && name.size() <= 64 && name != "." && name != ".." &&
                  std::all_of(name.begin(), name.end(), [](char c) {
                    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                           (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
                  });
  if (!ok) {
    throw Error(where,
                "'" + std::string(name) + "' is not a name: 1-64 characters of A-Z a-z 0-9 _ - .");
  }
}

std::string governance_xml() {
  return R"(<?xml version="1.0" encoding="utf-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>
        <id_range><min>0</min><max>230</max></id_range>
      </domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>SIGN</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}

std::string permissions_xml(const std::string& subject_rfc2253, SecurityRole role,
                            std::string_view session) {
  const std::time_t now = std::time(nullptr);
  const RoleTopics topics = role_topics(role);
  const std::string partition = "hapsim." + std::string(session);
  std::ostringstream xml;
  xml << R"(<?xml version="1.0" encoding="utf-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name=")"
      << role_name(role) << R"(">
      <subject_name>)"
      << subject_rfc2253 << R"(</subject_name>
      <validity>
        <not_before>)"
      << xml_date(now - 24 * 3600) << R"(</not_before>
        <not_after>)"
      << xml_date(now + 10L * 365 * 24 * 3600) << R"(</not_after>
      </validity>
      <allow_rule>
        <domains>
          <id_range><min>0</min><max>230</max></id_range>
        </domains>
)" << criteria("publish", topics.publish, partition)
      << criteria("subscribe", topics.subscribe, partition) << R"(      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)";
  return xml.str();
}

SecurityKeyDir SecurityKeyDir::init(const std::filesystem::path& dir, std::string_view session,
                                    const std::vector<std::string>& devices) {
  (void)session_partition(session);  // the names a session may have
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_empty(dir, ec)) {
    throw Error(dir.string(), "exists and is not empty: keys init makes a new session's keys");
  }
  for (const std::string& d : devices)
    check_identity_name(d, "--device");
  make_private_dir(dir / "private");
  make_private_dir(dir / "identities");
  ::chmod(dir.c_str(), 0755);
  const SecurityKeyDir keys(dir);
  const std::string s(session);
  const KeyPair id_ca = make_ca({s, "identity CA", "hapsim " + s + " identity CA"});
  const KeyPair perm_ca = make_ca({s, "permissions CA", "hapsim " + s + " permissions CA"});
  write_text_file(dir / "private" / "identity_ca.key", id_ca.key_pem, kPrivate);
  write_text_file(dir / "private" / "permissions_ca.key", perm_ca.key_pem, kPrivate);
  write_text_file(keys.identity_ca(), id_ca.cert_pem, kPublic);
  write_text_file(keys.permissions_ca(), perm_ca.cert_pem, kPublic);
  write_text_file(dir / "session", s + "\n", kPublic);
  write_text_file(dir / "governance.xml", governance_xml(), kPublic);
  write_text_file(keys.governance(), smime_sign(governance_xml(), perm_ca), kPublic);
  write_text_file(keys.crl(), make_crl(id_ca, {}), kPublic);
  write_text_file(dir / "revoked", "", kPublic);
  keys.add("serve", SecurityRole::kServe);
  keys.add("instructor", SecurityRole::kInstructor);
  keys.add("viewer", SecurityRole::kViewer);
  for (const std::string& d : devices)
    keys.add(d, SecurityRole::kDevice);
  return keys;
}

void SecurityKeyDir::add(std::string_view name, SecurityRole role) const {
  check_identity_name(name, "identity");
  const std::filesystem::path where = identity(name);
  std::error_code ec;
  if (std::filesystem::exists(where, ec)) {
    throw Error(where.string(), "exists: choose another name (or revoke it first)");
  }
  const std::string s = session();
  const KeyPair id_ca = read_pair(dir_ / "private" / "identity_ca.key", identity_ca());
  const KeyPair perm_ca = read_pair(dir_ / "private" / "permissions_ca.key", permissions_ca());
  const KeyPair me = make_identity({s, std::string(role_name(role)), std::string(name)}, id_ca);
  const std::string permissions = permissions_xml(subject_name_rfc2253(me.cert_pem), role, s);
  make_private_dir(where);
  write_text_file(where / "key.pem", me.key_pem, kPrivate);
  write_text_file(where / "cert.pem", me.cert_pem, kPublic);
  write_text_file(where / "permissions.xml", permissions, kPublic);
  write_text_file(where / "permissions.p7s", smime_sign(permissions, perm_ca), kPublic);
  write_text_file(where / "role", std::string(role_name(role)) + "\n", kPublic);
}

std::string SecurityKeyDir::revoke(std::string_view name) const {
  check_identity_name(name, "identity");
  const std::filesystem::path where = identity(name);
  const std::string serial = serial_hex(read_text_file(where / "cert.pem"));
  const KeyPair id_ca = read_pair(dir_ / "private" / "identity_ca.key", identity_ca());
  std::string list = read_text_file(dir_ / "revoked");
  list += serial + " " + std::string(name) + "\n";
  std::vector<std::string> serials;
  std::istringstream lines(list);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty())
      serials.push_back(line.substr(0, line.find(' ')));
  }
  write_text_file(crl(), make_crl(id_ca, serials), kPublic);
  write_text_file(dir_ / "revoked", list, kPublic);
  std::error_code ec;
  std::filesystem::remove_all(where, ec);
  return serial;
}

std::string SecurityKeyDir::session() const {
  const std::string s = trim(read_text_file(dir_ / "session"));
  check_identity_name(s, (dir_ / "session").string());
  return s;
}

std::string read_role(const SecurityKeyDir& keys, std::string_view name) {
  return trim(read_text_file(keys.identity(name) / "role"));
}

std::vector<std::string> SecurityKeyDir::identities() const {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir_ / "identities", ec)) {
    if (e.is_directory())
      names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace hapsim::net
