#pragma once
// Which format a log given to a tool (`--log`, `--log-map`) is in, and so how to read it: our drive log,
// our averaged log, VESC Tool's realtime log (detected by its header), or a CSV a user's column map
// describes. Every one is a LogMap, read by MappedLogReader: instantaneous maps through DriveLogReader,
// averaged ones through read_averaged_log (docs/drive-log.md).

#include <string>

#include "rpem/io/averaged_log.hpp"
#include "rpem/io/log_map.hpp"
#include "rpem/io/mapped_log.hpp"

namespace rpem::io {

struct LogSource {
  std::string path;
  LogMap map;
  std::string format;  ///< what was detected or given, for the tools' messages
  [[nodiscard]] bool averaged() const noexcept { return map.averaged(); }
};

/// The log at `log_path` as `map_path` describes it (a YAML column map; ConfigError if it is bad), or, with
/// `map_path` empty, as its first line says: a header starting with ms_today is VESC Tool's realtime log
/// (refused, naming the VESC Tool version that added it, when it lacks a column rpem needs, and when it is
/// VESC Tool 1.11–1.16's log without header), a header with t_start our averaged log, any other our
/// drive log. Throws DriveLogError if the file cannot be read.
[[nodiscard]] LogSource log_source(const std::string& log_path, const std::string& map_path = "");

/// One line for the tools: what was read as what, how many rows and samples, and what the time rules did
/// ("vesc.csv as VESC Tool realtime log (…): 8567 rows, 8566 averaged samples (the first row opens the
/// first window); 1 midnight wrap; 12 rows shared their millisecond with the row before").
[[nodiscard]] std::string describe(const LogSource& source, const AveragedLogRead& read);
/// The reader's part of it: wraps, ties, a cut last row (empty when there were none).
[[nodiscard]] std::string describe(const ReadRepairs& repairs);

}  // namespace rpem::io
