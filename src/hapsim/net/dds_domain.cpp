#include "hapsim/net/dds_domain.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <system_error>

namespace hapsim::net {

namespace {

// Names and addresses go into XML: letters, digits and . : - _ only, so nothing can end the
// attribute or add an element.
bool plain(const std::string& text) {
  return !text.empty() && text.size() <= 64 && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == ':' || c == '-' ||
           c == '_';
  });
}

void replace_once(std::string& text, const std::string& from, const std::string& to,
                  const std::filesystem::path& file) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) {
    throw Error(file.string(), "expected " + from + " in the shipped config to replace");
  }
  text.replace(at, from.size(), to);
}

}  // namespace

DdsDomain::DdsDomain(dds_domainid_t domain, const std::filesystem::path& default_config,
                     const DdsNetwork& network) {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  const bool user_config = uri != nullptr && *uri != '\0';
  if (network.interface.empty() && !network.peers.empty()) {
    throw Error("--peer", "give --interface too (the peers are reached through it)");
  }
  if (!network.interface.empty() && !plain(network.interface)) {
    throw Error("--interface",
                "'" + network.interface + "' is not an interface name (letters, digits, . : - _)");
  }
  std::string peers = "<Peer address=\"127.0.0.1\"/>";
  for (const std::string& peer : network.peers) {
    if (!plain(peer)) {
      throw Error("--peer", "'" + peer + "' is not a host name or address");
    }
    peers += "<Peer address=\"" + peer + "\"/>";
  }
  const std::string on_interface =
      network.interface.empty()
          ? std::string()
          : " on interface " + network.interface +
                (network.peers.empty() ? ""
                                       : ", " + std::to_string(network.peers.size()) + " peer(s)");
  secure_ = !network.security.empty();
  const std::string secured = secure_ ? ", DDS Security (" + network.security_label + ")" : "";
  // Cyclone reads a comma-separated list of files and XML fragments, later ones adding to and
  // overriding earlier ones: the user's config or ours first, then the network, then security.
  std::string sources;
  if (user_config) {
    config_ = std::string("CYCLONEDDS_URI=") + uri + on_interface + secured;
    if (network.interface.empty() && !secure_) {
      return;  // Cyclone reads CYCLONEDDS_URI itself when the first participant joins
    }
    sources = uri;
    if (!network.interface.empty()) {
      sources += ",<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"" +
                 network.interface + "\"/></Interfaces></General><Discovery><Peers>" + peers +
                 "</Peers></Discovery></Domain></CycloneDDS>";
    }
  } else {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(default_config, ec)) {
      throw Error(default_config.string(), "no such Cyclone DDS config (set CYCLONEDDS_URI)");
    }
    config_ = default_config.string() + on_interface + secured;
    if (network.interface.empty()) {
      sources = "file://" + std::filesystem::absolute(default_config).string();
    } else {
      std::ifstream in(default_config);
      std::string xml{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      replace_once(xml, "<NetworkInterface name=\"lo\"",
                   "<NetworkInterface name=\"" + network.interface + "\"", default_config);
      replace_once(xml, "<Peer address=\"127.0.0.1\"/>", peers, default_config);
      sources = xml;
    }
  }
  if (secure_) {
    sources += "," + network.security;
  }
  domain_ = DdsEntity(
      check_dds(dds_create_domain(domain, sources.c_str()), "creating domain from " + config_));
}

}  // namespace hapsim::net
