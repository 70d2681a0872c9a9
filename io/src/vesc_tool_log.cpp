#include "rpem/io/vesc_tool_log.hpp"
#include "rpem/io/number_text.hpp"

#include <algorithm>
#include <string>
#include <string_view>

#include "rpem/io/errors.hpp"
#include "rpem/io/vesc_tool_columns.hpp"

namespace rpem::io {
namespace {

/// A column list of vesc_tool_columns.hpp as a header version's.
template <std::size_t N>
std::vector<std::string_view> list(const std::array<std::string_view, N>& columns) {
  return {columns.begin(), columns.end()};
}

}  // namespace

const std::vector<VescToolHeader>& vesc_tool_headers() {
  static const std::vector<VescToolHeader> headers{
      {"1.17 to 1.19", "vedderb/vesc_tool 95f18604 (2019-09-03, \"Added header to RT CSV log\")", list(vesc_tool::kValues)},
      {"1.20 test builds", "vedderb/vesc_tool 5986063b (2019-09-17)",
       list(vesc_tool::join(vesc_tool::kValues, vesc_tool::kDqVoltages, vesc_tool::kGnss))},
      {"1.20 and later", "vedderb/vesc_tool 408f78fc (2019-09-27, v1.20)", list(vesc_tool::kColumns120)},
  };
  return headers;
}

const VescToolHeader* identify_vesc_tool_header(const std::vector<std::string>& cells) {
  for (const VescToolHeader& h : vesc_tool_headers()) {
    if (std::equal(h.columns.begin(), h.columns.end(), cells.begin(), cells.end())) return &h;
  }
  return nullptr;
}

LogMap vesc_tool_log_map() { return parse_log_map(vesc_tool_map_text(), "builtin:config/log-maps/vesc-tool.yaml"); }

void check_vesc_tool_header(const std::string& path, std::size_t line, const std::vector<std::string>& cells) {
  const VescToolHeader* version = identify_vesc_tool_header(cells);
  const LogMap map = vesc_tool_log_map();
  std::vector<std::string> read;
  if (map.time) read.push_back(map.time->column.name);
  for (const MappedColumn& c : map.columns) {
    if (!c.optional) read.push_back(c.column.name);
  }
  for (const std::string& name : read) {
    if (std::find(cells.begin(), cells.end(), name) != cells.end()) continue;
    // The first version whose header has the column added it.
    const auto added = std::find_if(vesc_tool_headers().begin(), vesc_tool_headers().end(), [&](const VescToolHeader& h) {
      return std::find(h.columns.begin(), h.columns.end(), name) != h.columns.end();
    });
    std::string reason = std::string("not in this VESC Tool realtime log (") +
                         (version ? std::string("the header of VESC Tool ") + version->versions
                                  : std::string("a header of no VESC Tool version known")) +
                         "), and rpem needs it";
    if (added == vesc_tool_headers().begin()) {
      // Every header VESC Tool writes has it: no version to record with, the header is not VESC Tool's own.
      reason += std::string("; every VESC Tool header has it (since ") + added->source +
                "): this header was edited, or written by another logger that leaves it out";
    } else if (added != vesc_tool_headers().end()) {
      const std::string_view versions(added->versions);
      const std::string_view first = versions.substr(0, versions.find(' '));
      reason += std::string("; VESC Tool ") + added->versions + " added it (" + added->source +
                "): record the log with VESC Tool " + std::string(first) + " or later";
    }
    throw DriveLogError(path, line, 0, "column " + name, reason);
  }
}

bool is_headerless_vesc_tool_row(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  if (line.empty() || line.back() != ';') return false;
  line.remove_suffix(1);
  std::size_t n = 0;
  while (true) {
    const std::size_t sep = line.find(';');
    const std::string_view cell = line.substr(0, sep);
    if (!is_number_text(cell)) return false;
    ++n;
    if (sep == std::string_view::npos) break;
    line.remove_prefix(sep + 1);
  }
  return n == vesc_tool::kValues.size();  // 1.11–1.16: the values every later version writes first
}

}  // namespace rpem::io
