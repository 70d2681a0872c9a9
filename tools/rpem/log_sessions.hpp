#pragma once
// --log as `rpem diagnose` and `rpem figures` take it: one log, or a folder's logs (log_folder.hpp's order) joined
// as one machine's sessions (analysis::load_sessions; docs/diagnose.md, "A folder of logs").

#include <cstdint>
#include <functional>
#include <string>

#include "rpem/analysis/diagnose/log_data.hpp"

namespace rpem::tools {

/// The log at `path`, or the logs of the folder at `path` joined as sessions.
[[nodiscard]] analysis::LogData load_log_or_sessions(const std::string& path, const core::MachineSi& machine,
                                                     const analysis::LogOptions& options,
                                                     const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

/// What `log` was read as, a line per log, and where a folder's sessions lie on the joined time axis, on stderr
/// after `tool` ("rpem diagnose").
void print_log_read(const char* tool, const analysis::LogData& log);

}  // namespace rpem::tools
