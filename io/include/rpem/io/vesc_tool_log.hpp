#pragma once
// VESC Tool's realtime-data log (docs/drive-log.md, "VESC Tool logs"): the CSV that VESC Tool (desktop and
// mobile) writes while "RT data logging" is on — semicolon-separated, one row per COMM_GET_VALUES reply,
// header `ms_today;input_voltage;…`. It is read through a column map like any other CSV
// (config/log-maps/vesc-tool.yaml, compiled in); this file knows the header of every VESC Tool version, so
// that a log lacking a column the estimator needs is refused with the version that added it.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rpem/io/log_map.hpp"

namespace rpem::io {

/// One header version of the log, as VESC Tool's source writes it (vedderb/vesc_tool, vescinterface.cpp).
struct VescToolHeader {
  const char* versions;                   ///< the VESC Tool releases that write it
  const char* source;                     ///< the commit that introduced it
  std::vector<std::string_view> columns;  ///< without the empty cell after the trailing ';'
};

/// Every header version found in VESC Tool's history, oldest first (docs/drive-log.md lists them).
[[nodiscard]] const std::vector<VescToolHeader>& vesc_tool_headers();

/// The version whose header is exactly `cells` (the empty cell after a trailing ';' dropped), or nothing.
[[nodiscard]] const VescToolHeader* identify_vesc_tool_header(const std::vector<std::string>& cells);

/// The map of config/log-maps/vesc-tool.yaml (compiled in).
[[nodiscard]] const std::string& vesc_tool_map_text();
[[nodiscard]] LogMap vesc_tool_log_map();

/// Throws DriveLogError (file:line) if a column the map reads is missing from `cells`, naming the header
/// version the file has and the VESC Tool version that added the column.
void check_vesc_tool_header(const std::string& path, std::size_t line, const std::vector<std::string>& cells);

/// True if `line` looks like a row of VESC Tool 1.11–1.16's log, which had no header: 22 numbers, each
/// followed by ';'.
[[nodiscard]] bool is_headerless_vesc_tool_row(std::string_view line);

}  // namespace rpem::io
