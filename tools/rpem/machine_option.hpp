#pragma once
// --config, as every subcommand that reads a log takes it: the machine's file, or without one the built-in paper
// machine — said, since a log of another machine is then judged against the paper's ratings (its plausibility
// limits name "the configured machine") and estimated from the paper's values.

#include <string>

#include "rpem/io/machine_config.hpp"

namespace rpem::tools {

/// The file at `path`; "" : the built-in configuration, with a note on stderr ("`tool`: note: …").
[[nodiscard]] io::MachineConfig machine_config_or_builtin(const std::string& path, const char* tool);

}  // namespace rpem::tools
