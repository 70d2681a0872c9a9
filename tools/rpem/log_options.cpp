#include "log_options.hpp"

namespace rpem::tools {

void add_log_options(CLI::App& cmd, std::string& log, std::string& log_map, const std::string& purpose, LogPath path) {
  std::string formats =
      "drive log, averaged log or VESC Tool realtime log (detected by its header), or any CSV with --log-map "
      "(docs/drive-log.md)";
  if (path == LogPath::kFileOrFolder) formats += "; or a folder of them, each on its own (\"A folder of logs\")";
  if (path == LogPath::kFileOrSessions)
    formats += "; or a folder of them, one machine's sessions taken together (docs/drive-log.md, \"A folder of logs\")";
  CLI::Option* log_option =
      cmd.add_option("--log", log, purpose.empty() ? formats : purpose + ": " + formats)
          ->check(path == LogPath::kFile ? CLI::Validator(CLI::ExistingFile) : CLI::Validator(CLI::ExistingPath));
  CLI::Option* map_option = add_log_map_option(cmd, log_map);
  if (purpose.empty()) {
    log_option->required();
  } else {
    map_option->needs(log_option);
  }
}

CLI::Option* add_log_map_option(CLI::App& cmd, std::string& log_map) {
  return cmd
      .add_option("--log-map", log_map, "column map (YAML) saying how to read the log (docs/drive-log.md, \"Column maps\")")
      ->check(CLI::ExistingFile);
}

}  // namespace rpem::tools
