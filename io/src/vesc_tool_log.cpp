#include "rpem/io/vesc_tool_log.hpp"

#include <algorithm>
#include <charconv>

#include "rpem/io/errors.hpp"

namespace rpem::io {
namespace {

// The column groups VESC Tool's openRtLogFile() writes, in its order (vedderb/vesc_tool, vescinterface.cpp).
using Columns = std::vector<std::string_view>;
const Columns kValues{
    "ms_today",       "input_voltage",    "temp_mos_max",      "temp_mos_1",      "temp_mos_2",         "temp_mos_3",
    "temp_motor",     "current_motor",    "current_in",        "d_axis_current",  "q_axis_current",     "erpm",
    "duty_cycle",     "amp_hours_used",   "amp_hours_charged", "watt_hours_used", "watt_hours_charged", "tachometer",
    "tachometer_abs", "encoder_position", "fault_code",        "vesc_id"};
const Columns kDqVoltages{"d_axis_voltage", "q_axis_voltage"};
const Columns kSetup{"ms_today_setup",
                     "amp_hours_setup",
                     "amp_hours_charged_setup",
                     "watt_hours_setup",
                     "watt_hours_charged_setup",
                     "battery_level",
                     "battery_wh_tot",
                     "current_in_setup",
                     "current_motor_setup",
                     "speed_meters_per_sec",
                     "tacho_meters",
                     "tacho_abs_meters",
                     "num_vescs"};
const Columns kImu{"ms_today_imu", "roll", "pitch", "yaw", "accX", "accY", "accZ", "gyroX", "gyroY", "gyroZ"};
const Columns kGnss{"gnss_posTime", "gnss_lat", "gnss_lon", "gnss_alt", "gnss_gVel", "gnss_vVel", "gnss_hAcc", "gnss_vAcc"};

Columns join(std::initializer_list<const Columns*> parts) {
  Columns c;
  for (const Columns* p : parts) c.insert(c.end(), p->begin(), p->end());
  return c;
}

/// The number of values in a row of VESC Tool 1.11–1.16, which wrote no header (the 22 of kValues).
constexpr std::size_t kHeaderlessValues = 22;

}  // namespace

const std::vector<VescToolHeader>& vesc_tool_headers() {
  static const std::vector<VescToolHeader> headers{
      {"1.17 to 1.19", "vedderb/vesc_tool 95f18604 (2019-09-03, \"Added header to RT CSV log\")", join({&kValues})},
      {"1.20 test builds", "vedderb/vesc_tool 5986063b (2019-09-17)", join({&kValues, &kDqVoltages, &kGnss})},
      {"1.20 and later", "vedderb/vesc_tool 408f78fc (2019-09-27, v1.20)",
       join({&kValues, &kDqVoltages, &kSetup, &kImu, &kGnss})},
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
  for (const MappedColumn& c : map.columns) read.push_back(c.column.name);
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
    if (added != vesc_tool_headers().end()) {
      reason += std::string("; VESC Tool ") + added->versions + " added it (" + added->source +
                "): record the log with VESC Tool 1.20 or later";
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
    double v = 0.0;
    const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
    if (cell.empty() || ec != std::errc() || end != cell.data() + cell.size()) return false;
    ++n;
    if (sep == std::string_view::npos) break;
    line.remove_prefix(sep + 1);
  }
  return n == kHeaderlessValues;
}

}  // namespace rpem::io
