// `hapsim keys`: a secure session's keys (SPEC §13, docs/security.md), made on one machine and
// copied to the others. `init DIR --session NAME` makes the session CA, the permissions CA, the
// signed governance and the identities serve, instructor, viewer and one per `--device HOST`;
// `add-device`, `add-viewer` and `add-instructor NAME` add one; `revoke NAME` puts its certificate
// on the session CA's revocation list (refused at its next handshake with anyone holding the new
// crl.pem); `list` says what DIR holds.
#include "commands.h"

#include "hapsim/net/security_key_dir.h"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace hapsim::app {
namespace {

struct KeysArgs {
  std::string dir;
  std::string session;
  std::vector<std::string> devices;
  std::string name;
};

void print_identities(const net::SecurityKeyDir& keys) {
  for (const std::string& name : keys.identities()) {
    std::string role;
    try {
      role = net::read_role(keys, name);
    } catch (const std::exception&) {
      role = "?";
    }
    std::printf("identity     %-16s %s\n", name.c_str(), role.c_str());
  }
}

void add_named(CLI::App* group, const char* verb, net::SecurityRole role, const char* what) {
  auto args = std::make_shared<KeysArgs>();
  CLI::App* cmd = group->add_subcommand(verb, what);
  cmd->add_option("name", args->name, "The identity's name (a device: its host name)")->required();
  cmd->add_option("--dir", args->dir, "The session's key directory (made by hapsim keys init)")
      ->envname("HAPSIM_SECURE_DIR")
      ->required();
  cmd->callback([args, role] {
    const net::SecurityKeyDir keys(args->dir);
    keys.add(args->name, role);
    std::printf("added        %s (%s) in %s: copy %s and the session's public files to its host\n",
                args->name.c_str(), std::string(net::role_name(role)).c_str(), args->dir.c_str(),
                keys.identity(args->name).c_str());
  });
}

}  // namespace

void add_keys_command(CLI::App& app) {
  CLI::App* group = app.add_subcommand(
      "keys", "A secure session's keys: CAs, signed governance and permissions, identities");
  group->require_subcommand(1);

  auto init = std::make_shared<KeysArgs>();
  CLI::App* cmd = group->add_subcommand(
      "init",
      "Make DIR: session and permissions CAs, governance, identities serve, instructor, "
      "viewer and one per --device");
  cmd->add_option("dir", init->dir, "The new key directory (must not exist or be empty)")
      ->required();
  cmd->add_option("--session", init->session, "The session these keys are for")->required();
  cmd->add_option("--device", init->devices,
                  "A device host's identity, by its host name (repeat; default 'device')");
  cmd->callback([init] {
    const std::vector<std::string> devices =
        init->devices.empty() ? std::vector<std::string>{"device"} : init->devices;
    const net::SecurityKeyDir keys = net::SecurityKeyDir::init(init->dir, init->session, devices);
    std::printf("keys         session '%s' in %s (CA keys in %s/private: keep them here)\n",
                init->session.c_str(), init->dir.c_str(), init->dir.c_str());
    print_identities(keys);
  });

  add_named(group, "add-device", net::SecurityRole::kDevice,
            "A device host's identity: publishes its device states");
  add_named(group, "add-viewer", net::SecurityRole::kViewer,
            "A viewer's identity: reads scenes and views, publishes nothing");
  add_named(group, "add-instructor", net::SecurityRole::kInstructor,
            "An instructor's identity: reads what a viewer reads, sends commands");

  auto revoke = std::make_shared<KeysArgs>();
  CLI::App* rev = group->add_subcommand(
      "revoke", "Revoke NAME: refused at its next handshake by every host with the new crl.pem");
  rev->add_option("name", revoke->name, "The identity to revoke")->required();
  rev->add_option("--dir", revoke->dir, "The session's key directory")
      ->envname("HAPSIM_SECURE_DIR")
      ->required();
  rev->callback([revoke] {
    const net::SecurityKeyDir keys(revoke->dir);
    const std::string serial = keys.revoke(revoke->name);
    std::printf("revoked      %s (serial %s): copy %s to every host and restart what runs there\n",
                revoke->name.c_str(), serial.c_str(), keys.crl().c_str());
  });

  auto list = std::make_shared<KeysArgs>();
  CLI::App* ls = group->add_subcommand("list", "The session and identities of DIR");
  ls->add_option("dir", list->dir, "The key directory")->envname("HAPSIM_SECURE_DIR")->required();
  ls->callback([list] {
    const net::SecurityKeyDir keys(list->dir);
    std::printf("keys         session '%s' in %s\n", keys.session().c_str(), list->dir.c_str());
    print_identities(keys);
  });
}

}  // namespace hapsim::app
