#include "rpem/daemon/credentials.hpp"

#include <algorithm>
#include <filesystem>
#include <vector>

#include "rpem/auth/key_file.hpp"

namespace rpem::daemon {

DaemonKeys load_credential_keys(const char* directory) {
  DaemonKeys keys;
  if (directory == nullptr || *directory == '\0') return keys;
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory, ec)) files.push_back(entry.path());
  if (ec) throw auth::KeyError(std::string(directory) + ": cannot read the credentials directory: " + ec.message());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    std::string name = file.filename().string();
    if (name.rfind("rpem_", 0) == 0) name.erase(0, 5);  // LoadCredential=rpem:DIR names DIR/x "rpem_x"
    const bool command = name.rfind("command", 0) == 0, publish = name.rfind("publish", 0) == 0;
    if (!command && !publish) continue;
    auth::Key key = auth::load_key_file(file.string());
    const std::int32_t id = key.id();
    if (publish) {
      if (keys.publish) throw auth::KeyError(file.string() + ": a second publish key; rpemd signs with one");
      keys.publish = std::move(key);
    } else if (!keys.command.add(std::move(key))) {
      throw auth::KeyError(file.string() + ": key id " + std::to_string(id) +
                           (keys.command.find(id) != nullptr ? " is already used by another command key"
                                                             : ": more than two command keys (the current and the next)"));
    }
  }
  return keys;
}

std::string command_key_problem(const LiveConfig& live, const auth::Keyring& command_keys) {
  if (!live.commands_enabled || live.command_authentication == CommandAuthentication::kNone || !command_keys.empty())
    return "";
  return "commands are enabled but no command key is configured: give rpemd a key file as the credential rpem_command "
         "(LoadCredential=, docs/rpemd.md \"Authentication\"), or — where LCM cannot leave this host — set "
         "daemon.commands.authentication: none";
}

CredentialCheck check_credentials(const LiveConfig& live, const char* directory) {
  CredentialCheck check{load_credential_keys(directory), ""};
  check.problem = command_key_problem(live, check.keys.command);
  return check;
}

}  // namespace rpem::daemon
