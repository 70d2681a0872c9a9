#pragma once
// Key files (docs/rpemd.md, "Keys"): one line of text,
//     rpem-key-1 <key id> <64 hex digits: the 32-byte key>
// readable by its owner only — a file that its group or others may read or write is refused, so is
// anything else in it. rpemd reads them from $CREDENTIALS_DIRECTORY (systemd's LoadCredential=), the
// rpem tool from --key FILE; a key is never in the YAML or on a command line.

#include <string>

#include "rpem/auth/mac.hpp"

namespace rpem::auth {

// KeyError (key.hpp): a key file that cannot be used, naming the file and why.

/// Parses a key file's text, decoding the key straight into its locked memory (wiping `text` is the
/// caller's); `where` names it in errors.
[[nodiscard]] Key parse_key(const std::string& text, const std::string& where);
/// The key file's text for `key`: it holds the key, so wipe it when done (as write_key_file does).
[[nodiscard]] std::string format_key(const Key& key);
/// Reads and checks a key file (owner-only permissions, format).
[[nodiscard]] Key load_key_file(const std::string& path);
/// A fresh random key (libsodium's randombytes_buf: the kernel's getrandom).
[[nodiscard]] Key generate_key(std::int32_t id);
/// Writes a key file with mode 0600, refusing to replace an existing file.
void write_key_file(const std::string& path, const Key& key);

}  // namespace rpem::auth
