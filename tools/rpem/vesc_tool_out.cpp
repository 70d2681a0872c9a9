#include "vesc_tool_out.hpp"

#include <cmath>
#include <cstdio>
#include <optional>

#include "commands.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "rpem/io/number_format.hpp"
#include "rpem/sim/vesc_tool_log.hpp"

namespace rpem::tools {

void add_vesc_tool_options(CLI::App* cmd, VescToolOptions& o) {
  writes_file(cmd->add_option(
      "--vesc-tool-out", o.out,
      "write the emulated VESC's reads as VESC Tool's realtime-data log (semicolon CSV, docs/scenarios.md)"));
  writes_file(cmd->add_option("--vesc-tool-truth", o.truth, "also write the truth of every row (CSV)"));
  cmd->add_option("--vesc-tool-rate", o.link.rate_Hz, "mean rows per second [Hz]")
      ->check(CLI::Range(0.5, 100.0))
      ->capture_default_str();
  cmd->add_option("--vesc-tool-jitter", o.link.jitter, "intervals between rows uniform in (1 +- jitter)/rate")
      ->check(CLI::Range(0.0, 0.95))
      ->capture_default_str();
  cmd->add_option("--vesc-tool-loss", o.link.loss, "probability that a poll is lost (VESC Tool then waits its 1 s timeout)")
      ->check(CLI::Range(0.0, 0.5))
      ->capture_default_str();
  cmd->add_option("--vesc-tool-seed", o.link.seed, "seed of the intervals and losses")->capture_default_str();
  cmd->add_option("--vesc-tool-start", o.start_utc, "UTC time of day at t = 0, HH:MM:SS[.mmm] (ms_today wraps at midnight)")
      ->capture_default_str();
}

long long parse_time_of_day_ms(const std::string& text) {
  int h = 0, m = 0, s = 0, ms = 0, used = 0;
  if (std::sscanf(text.c_str(), "%2d:%2d:%2d%n", &h, &m, &s, &used) != 3) return -1;
  std::size_t at = static_cast<std::size_t>(used);
  if (at < text.size()) {
    if (text[at] != '.' || text.size() - at != 4) return -1;
    for (std::size_t k = at + 1; k < text.size(); ++k) {
      if (text[k] < '0' || text[k] > '9') return -1;
      ms = ms * 10 + (text[k] - '0');
    }
  }
  if (h < 0 || h > 23 || m < 0 || m > 59 || s < 0 || s > 59) return -1;
  return ((h * 60LL + m) * 60LL + s) * 1000LL + ms;
}

int run_vesc_tool_log(sim::Scenario scenario, const VescToolOptions& o) {
  const long long start_ms = parse_time_of_day_ms(o.start_utc);
  if (start_ms < 0) {
    std::fprintf(stderr, "rpem sim: --vesc-tool-start '%s': expected HH:MM:SS or HH:MM:SS.mmm (UTC)\n", o.start_utc.c_str());
    return kExitUsage;
  }
  sim::VescToolLink link = o.link;
  link.start_ms_today = start_ms;
  const std::string name = scenario.name;
  const double duration_s = scenario.duration_s;
  sim::VescToolLogWriter log(o.out);
  std::optional<sim::VescToolTruthWriter> truth;
  if (!o.truth.empty()) truth.emplace(o.truth);
  sim::VescToolSession session(std::move(scenario), link);
  Progress progress("rpem sim");
  sim::VescToolRow row;
  sim::VescToolTruth row_truth;
  const auto total_ms = static_cast<std::uint64_t>(std::llround(duration_s * 1e3));
  while (session.next(row, row_truth)) {
    log.write(row);
    if (truth) truth->write(row_truth);
    progress.update(static_cast<std::uint64_t>(row_truth.t_ns / 1'000'000), total_ms);
  }
  const auto& n = session.counters();
  std::string summary = io::counted(n.rows, "VESC Tool row") + " of '" + name + "' written to " + o.out + " (" +
                        io::counted(n.lost_requests + n.lost_replies, "poll") + " lost)";
  progress.finish(summary);
  if (const std::uint64_t r = session.motor().simulator().rectifying_periods(); r > 0) {
    std::fprintf(stderr,
                 "rpem sim: warning: in %llu bridge-off periods the back EMF reached the DC link, where the "
                 "diodes would rectify (not modelled)\n",
                 static_cast<unsigned long long>(r));
  }
  return kExitOk;
}

}  // namespace rpem::tools
