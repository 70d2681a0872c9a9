#include "rpem/io/log_source.hpp"
#include "rpem/io/number_text.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

#include "rpem/io/errors.hpp"
#include "rpem/io/vesc_tool_log.hpp"

namespace rpem::io {
namespace {

/// Cells of a header line split at `separator`, trimmed of blanks and quotes; the empty cell after a
/// trailing separator dropped.
std::vector<std::string> header_cells(const std::string& line, char separator) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t sep = line.find(separator, start);
    std::string cell = line.substr(start, sep == std::string::npos ? std::string::npos : sep - start);
    const auto first = cell.find_first_not_of(" \t\r\"");
    const auto last = cell.find_last_not_of(" \t\r\"");
    cells.push_back(first == std::string::npos ? std::string() : cell.substr(first, last - first + 1));
    if (sep == std::string::npos) break;
    start = sep + 1;
  }
  if (cells.size() > 1 && cells.back().empty()) cells.pop_back();
  return cells;
}

/// A line of numbers only (two or more, at either separator): a data row where a header belongs.
bool numbers_only(const std::string& line) {
  for (char separator : {',', ';'}) {
    const std::vector<std::string> cells = header_cells(line, separator);
    const auto number = [](const std::string& c) { return is_number_text(c); };
    if (cells.size() >= 2 && std::all_of(cells.begin(), cells.end(), number)) return true;
  }
  return false;
}

}  // namespace

LogSource log_source(const std::string& log_path, const std::string& map_path) {
  // The tools read a log more than once (its format detected, its size for progress, its rows): a pipe would give
  // its rows to the first reading only.
  std::error_code ec;
  if (std::filesystem::exists(log_path, ec) && !std::filesystem::is_regular_file(log_path, ec)) {
    throw InputError(log_path, 0, 0, "",
                     "is not a regular file (a pipe, a device or a directory): the log is read more than once; write "
                     "it to a file first");
  }
  if (!map_path.empty()) return {log_path, load_log_map(map_path), "CSV read through the map " + map_path};

  std::ifstream in(log_path, std::ios::binary);
  if (!in) throw DriveLogError(log_path, 0, 0, "", "cannot open file");
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte-order mark
    if (line.find_first_not_of(" \t\r") != std::string::npos) break;
  }
  for (char separator : {';', ','}) {
    const std::vector<std::string> cells = header_cells(line, separator);
    if (cells.size() < 2 || cells.front() != "ms_today") continue;
    check_vesc_tool_header(log_path, line_no, cells);
    LogMap map = vesc_tool_log_map();
    map.separator = separator;  // VESC Tool writes ';' (and reads ',' too)
    const VescToolHeader* version = identify_vesc_tool_header(cells);
    return {log_path, std::move(map),
            version ? std::string("VESC Tool realtime log (the header of VESC Tool ") + version->versions + ")"
                    : std::string("VESC Tool realtime log (a header of no VESC Tool version known: columns read by name)")};
  }
  if (is_headerless_vesc_tool_row(line)) {
    throw DriveLogError(log_path, line_no, 0, "",
                        "a VESC Tool realtime log without header (VESC Tool 1.11 to 1.16, vedderb/vesc_tool 2323a806): "
                        "rpem reads columns by name, and its 22 values per row are those VESC Tool 1.17 to 1.19 named "
                        "(vedderb/vesc_tool 95f18604): put that header line first (docs/drive-log.md, \"Header "
                        "versions\"); its d/q voltages are then rebuilt from duty_cycle (\"Logs without d/q values\")");
  }
  if (numbers_only(line)) {
    throw DriveLogError(log_path, line_no, 0, "",
                        "holds numbers, not column names: the file has no header (cut from a longer log?). rpem reads "
                        "columns by the header's names: put the logger's header line first (VESC Tool's by version: "
                        "docs/drive-log.md, \"Header versions\"), or read the file through a map with `header: false` "
                        "(--log-map)");
  }
  for (const std::string& cell : header_cells(line, ',')) {
    if (cell == "t_start") return {log_path, averaged_log_map(), "averaged log"};
  }
  return {log_path, drive_log_map(), "drive log"};
}

std::string describe(const ReadRepairs& r) {
  std::string s;
  if (r.wraps > 0)
    s += "; " + std::to_string(r.wraps) + (r.wraps == 1 ? " wrap" : " wraps") + " of the time column (midnight)";
  if (r.tied_rows > 0) {
    s += "; " + std::to_string(r.tied_rows) + (r.tied_rows == 1 ? " row shared its" : " rows shared their") +
         " time stamp with the row before (spread over its resolution)";
  }
  if (r.cut_line > 0) {
    s += "; its last line (" + std::to_string(r.cut_line) +
         ") is a row cut off while the file was written (unfinished, no newline after it): not read";
  }
  if (!r.never_recorded.empty()) {
    s += "; column" + std::string(r.never_recorded.size() > 1 ? "s " : " ");
    for (std::size_t k = 0; k < r.never_recorded.size(); ++k) s += (k > 0 ? ", " : "") + r.never_recorded[k];
    s += " named in the header but empty on every row: read as absent (the map marks them optional)";
  }
  for (const ReadRepairs::NoReading& n : r.no_reading) {
    s += "; " + n.column +
         (n.every_row
              ? " holds " + n.value + ", its logger's value for no reading, on every row: no such sensor, read as absent"
              : ": " + std::to_string(n.rows) + (n.rows == 1 ? " row holds " : " rows hold ") + n.value +
                    ", its logger's value for no reading: no reading there");
  }
  return s;
}

std::string describe(const LogSource& source, const AveragedLogRead& read) {
  std::string s = source.path + " as " + source.format + ": " + std::to_string(read.rows) + " rows, " +
                  std::to_string(read.rows - read.opening_rows - read.unknown_windows) + " averaged samples";
  if (read.opening_rows > 0) s += " (the first row opens the first window: its own began before the log)";
  if (read.unknown_windows > 0) {
    s += "; " + std::to_string(read.unknown_windows) +
         " windows unknown, not used: each begins or ends at a read stamped perhaps long after it was taken (a row " +
         "after the logger asked again, or a count its stamps cannot hold; docs/drive-log.md, \"Rows stamped late\")";
    // Over a tenth (where the regimes' rules name their keys too): the key that decides which rows are late replies.
    if (10 * read.unknown_windows > read.rows && source.map.request_timeout_s > 0.0) {
      char timeout[32];
      std::snprintf(timeout, sizeof timeout, "%.4g", source.map.request_timeout_s);
      s += std::string(". Key: request_timeout_s, ") + timeout + " s in " + source.map.name +
           " (a row that long after the one before is taken for a reply to a request asked again); a logger that waits "
           "longer for its replies needs a copy of the map with its own timeout (--log-map)";
    }
  }
  if (source.map.speed_pll.given()) {
    char lag[160];
    std::snprintf(lag, sizeof lag, "; each window's mean speed rebuilt from the PLL speeds at its two reads (lag %.4g ms)",
                  1e3 * source.map.speed_pll.ramp_lag_s());
    s += lag;
  }
  return s + describe(read.repairs);
}

}  // namespace rpem::io
