#pragma once
// `rpem sim --scenario S --vesc-tool-out LOG.csv [--vesc-tool-truth TRUTH.csv] [--vesc-tool-rate HZ …]`: the
// emulated VESC of a scenario logged as VESC Tool logs realtime data (sim/vesc_tool_session.hpp,
// sim/vesc_tool_log.hpp; docs/scenarios.md, "VESC Tool logs"). This file only parses options and writes.

#include <CLI/CLI.hpp>
#include <string>

#include "rpem/sim/scenario.hpp"
#include "rpem/sim/vesc_tool_session.hpp"

namespace rpem::tools {

struct VescToolOptions {
  std::string out;
  std::string truth;
  std::string start_utc = "12:00:00";  ///< UTC time of day at drive time 0, HH:MM:SS[.mmm]
  sim::VescToolLink link;
};

void add_vesc_tool_options(CLI::App* cmd, VescToolOptions& options);

/// Parses HH:MM:SS[.mmm] (00:00:00 to 23:59:59.999) to milliseconds since midnight; -1 if malformed.
[[nodiscard]] long long parse_time_of_day_ms(const std::string& text);

/// Writes the log (and its truth) until the scenario ends.
int run_vesc_tool_log(sim::Scenario scenario, const VescToolOptions& options);

}  // namespace rpem::tools
