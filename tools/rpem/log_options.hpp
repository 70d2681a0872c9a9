#pragma once
// --log and --log-map, as every subcommand that reads a drive log takes them (docs/drive-log.md): one text for
// what a log may be, one reading of it (io::log_source).

#include <CLI/CLI.hpp>
#include <string>

namespace rpem::tools {

/// What --log may name: a log; or also a folder of them, each log on its own (rpem estimate: log_folder.hpp) or the
/// logs as one machine's sessions, together (rpem thermal fit: analysis::join_sessions; rpem diagnose:
/// analysis::load_sessions).
enum class LogPath { kFile, kFileOrFolder, kFileOrSessions };

/// Adds --log and --log-map to `cmd`. Without `purpose` --log is required; with it (what the subcommand does
/// with a log, said before what a log may be) --log is optional and --log-map needs it.
void add_log_options(CLI::App& cmd, std::string& log, std::string& log_map, const std::string& purpose = "",
                     LogPath path = LogPath::kFile);

/// Adds --log-map alone, for a subcommand whose log is a positional argument (rpem replay).
CLI::Option* add_log_map_option(CLI::App& cmd, std::string& log_map);

}  // namespace rpem::tools
