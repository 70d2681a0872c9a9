#pragma once
// rpemd's keys (docs/rpemd.md, "Authentication"): key files (rpem/auth/key_file.hpp) in systemd's
// credentials directory, $CREDENTIALS_DIRECTORY — rpemd.service loads /etc/rpemd/keys with
// LoadCredential=rpem:/etc/rpemd/keys, so a file `command.key` there is the credential `rpem_command.key`.
//   [rpem_]command*   accepted on RPEM_COMMAND: one, or two while a key is being changed;
//   [rpem_]publish*   at most one: signs RPEM_ESTIMATE and RPEM_DIAGNOSTICS (unsigned without it).
// Read once at start-up; never from the YAML or the command line.

#include <optional>
#include <string>

#include "rpem/auth/mac.hpp"
#include "rpem/daemon/daemon_config.hpp"

namespace rpem::daemon {

struct DaemonKeys {
  auth::Keyring command;
  std::optional<auth::Key> publish;
};

/// The keys in `directory` (nullptr or empty: none). Throws auth::KeyError naming the file and why.
[[nodiscard]] DaemonKeys load_credential_keys(const char* directory);

/// Why rpemd cannot run this configuration with these command keys ("" if it can): commands enabled,
/// authentication required, no key.
[[nodiscard]] std::string command_key_problem(const LiveConfig& live, const auth::Keyring& command_keys);

/// The keys in `directory` for a service running `live`, and why it cannot run with them ("" if it can): start-up
/// and --check-config read them alike. Throws as load_credential_keys.
struct CredentialCheck {
  DaemonKeys keys;
  std::string problem;
};
[[nodiscard]] CredentialCheck check_credentials(const LiveConfig& live, const char* directory);

}  // namespace rpem::daemon
