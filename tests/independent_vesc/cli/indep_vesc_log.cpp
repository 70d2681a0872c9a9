// indep_vesc_log: writes a VESC Tool realtime-data log from the independent VESC generator
// (tests/independent_vesc/README.md).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "indep_drive/machine_config.hpp"
#include "indep_vesc/case.hpp"
#include "indep_vesc/generator.hpp"
#include "indep_vesc/scenario.hpp"

namespace {

constexpr int kExitUsage = 64;
constexpr int kExitData = 65;
constexpr int kExitConfig = 78;
constexpr int kExitIo = 74;  // EX_IOERR: a file that cannot be written

void apply_set(indep::vesc::Case& c, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("--set " + assignment + ": expected key=value");
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  double value = 0.0;
  try {
    std::size_t used = 0;
    value = std::stod(text, &used);
    if (used != text.size()) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw std::invalid_argument("--set " + key + ": '" + text + "' is not a number");
  }
  indep::vesc::set_parameter(c, key, value);
}

/// "HH:MM:SS" or "HH:MM:SS.mmm" → milliseconds since midnight.
double parse_time_of_day(const std::string& s) {
  int h = 0, m = 0;
  double sec = 0.0;
  char c1 = 0, c2 = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c%lf", &h, &c1, &m, &c2, &sec) != 5 || c1 != ':' || c2 != ':' || h < 0 || h > 23 ||
      m < 0 || m > 59 || sec < 0.0 || sec >= 60.0) {
    throw std::invalid_argument("--start-time '" + s + "': expected HH:MM:SS[.mmm]");
  }
  return (h * 3600.0 + m * 60.0 + sec) * 1000.0;
}

void write(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error(path + ": cannot be written");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Independent VESC Tool log generator: a sensorless (or Hall-sensored) VESC driving an outrunner, read by VESC Tool "
      "(tests/independent_vesc/README.md)"};
  std::string config, out, truth_path, scenario, start_time, off_voltage = "measured", trace;
  int trace_every = 125;
  std::uint64_t seed = 1;
  double duration = 600.0, rate = 11.0, poll_rate = 50.0;
  std::optional<double> psi_rel, r_rel;
  int header = indep::vesc::kNewestHeaderVersion;
  bool midnight = false, crlf = false, isothermal = false, no_vdq_filter = false, invert = false, hall = false;
  bool list_parameters = false;
  std::vector<std::string> sets;
  app.add_option("--config", config, "configuration YAML (its machine section)");
  app.add_option("--seed", seed, "seed of every random draw");
  app.add_option("--duration-s", duration, "length of the log [s]");
  app.add_option("--out", out, "the VESC Tool CSV");
  app.add_option("--truth", truth_path, "the truth JSON");
  app.add_option("--psi-m-rel", psi_rel, "true psi_m / configured - 1 (default: drawn, 10-30 % either way)");
  app.add_option("--r-s-rel", r_rel, "true R_s / configured - 1 at the reference temperature (default: drawn)");
  app.add_option("--rate-Hz", rate, "mean row rate the link allows [Hz]");
  app.add_option("--poll-rate-Hz", poll_rate, "VESC Tool's realtime-data poll rate setting [Hz]");
  app.add_option("--header-version", header, "0 (no header, 22 values), 1 (22), 2 (32), 3 (55, newest)");
  app.add_option("--start-time", start_time, "logger clock at the start, HH:MM:SS[.mmm] (default: drawn)");
  app.add_flag("--midnight", midnight, "start so that ms_today wraps at a third of the log");
  app.add_flag("--crlf", crlf, "Windows line ends");
  app.add_option("--scenario", scenario,
                 "scenario CSV (kind,duration_s,current_A[,ramp_s,until_erpm,erpm_per_s,external_Nm,friction_Nm,"
                 "viscous_Nm_s])");
  app.add_option("--off-voltage", off_voltage, "what v_d, v_q report with the bridge off: measured (firmware) or zero")
      ->check(CLI::IsMember({"measured", "zero"}));
  app.add_flag("--isothermal", isothermal, "constant temperatures (R_s and psi_m stay at their start values)");
  app.add_flag("--no-vdq-filter", no_vdq_filter, "firmware before 5.03: no speed-dependent filter on v_d, v_q");
  app.add_flag("--invert-direction", invert, "the VESC's m_invert_direction");
  app.add_flag("--hall", hall,
               "Hall-sensor mode (foc_sensor_mode = FOC_SENSOR_MODE_HALL, ideal sensors, the detected table); "
               "without --scenario the built-in Hall ride");
  app.add_option("--trace", trace, "per-cycle trace CSV of plant and firmware (every --trace-every cycles)");
  app.add_option("--trace-every", trace_every, "cycles between trace rows")->check(CLI::PositiveNumber);
  app.add_option("--set", sets, "numeric parameter key=value (repeatable; --list-parameters)");
  app.add_flag("--list-parameters", list_parameters, "print every --set key with its unit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitUsage;
  }
  if (list_parameters) {
    for (const auto& e : indep::vesc::parameter_catalogue()) std::cout << e.key << " [" << e.unit << "]\n";
    return 0;
  }
  if (config.empty() || out.empty()) {
    std::cerr << "indep_vesc_log: --config and --out are required\n";
    return kExitUsage;
  }

  indep::vesc::Case c;
  try {
    c.machine = indep::read_machine_config(config);
  } catch (const indep::ConfigError& e) {
    std::cerr << "indep_vesc_log: configuration error: " << e.what() << "\n";
    return kExitConfig;
  }
  try {
    c.seed = seed;
    c.duration_s = duration;
    c.draw.psi_m_rel = psi_rel;
    c.draw.r_s_rel = r_rel;
    c.poller.rate_Hz = rate;
    c.poller.poll_rate_Hz = poll_rate;
    c.format.header_version = header;
    c.format.midnight = midnight;
    c.format.crlf = crlf;
    if (!start_time.empty()) c.format.start_ms_today = parse_time_of_day(start_time);
    c.thermal.on = !isothermal;
    c.firmware.vdq_filter = !no_vdq_filter;
    c.firmware.invert_direction = invert;
    c.firmware.hall = hall;
    c.keep_cycle_trace = !trace.empty();
    c.trace_every = trace_every;
    c.firmware.off_voltage = off_voltage == "zero" ? indep::vesc::OffVoltage::zero : indep::vesc::OffVoltage::measured;
    for (const std::string& s : sets) apply_set(c, s);
    c = indep::vesc::resolve_defaults(c);
  } catch (const std::invalid_argument& e) {
    std::cerr << "indep_vesc_log: " << e.what() << "\n";
    return kExitUsage;
  }
  if (!scenario.empty()) {
    try {
      c.scenario = indep::vesc::read_scenario_csv(scenario);
    } catch (const indep::vesc::ScenarioError& e) {
      std::cerr << "indep_vesc_log: scenario error: " << e.what() << "\n";
      return kExitData;
    }
  }

  try {
    const indep::vesc::Result r = indep::vesc::generate(c);
    write(out, indep::vesc::vesc_tool_csv(r));
    if (!truth_path.empty()) write(truth_path, indep::vesc::truth_json(r));
    if (!trace.empty()) write(trace, indep::vesc::cycle_trace_csv(r));
    std::fprintf(stderr,
                 "indep_vesc_log: %zu rows (%d reads, %d replies lost) over %.1f s; true psi_m %.6g Wb (%+.1f %%), "
                 "R_s %.6g Ohm (%+.1f %%) at %.0f C; at the end %.6g Wb, %.6g Ohm\n",
                 r.rows.size(), r.reads, r.lost_replies, c.duration_s, r.true_at_reference.psi_m_Wb,
                 100.0 * (r.true_at_reference.psi_m_Wb / r.configured.psi_m_Wb - 1.0), r.true_at_reference.r_s_Ohm,
                 100.0 * (r.true_at_reference.r_s_Ohm / r.configured.r_s_Ohm - 1.0), c.thermal.reference_C, r.end_psi_m_Wb,
                 r.end_r_s_Ohm);
  } catch (const std::invalid_argument& e) {
    std::cerr << "indep_vesc_log: " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::runtime_error& e) {
    std::cerr << "indep_vesc_log: " << e.what() << "\n";
    return kExitIo;
  }
  return 0;
}
