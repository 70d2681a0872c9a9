// indep_thermal_plant: a drive log and its thermal truth from the independent three-node plant (README.md).
//   indep_thermal_plant --config CFG --seed N --duration-s X --rate-Hz 2 --out log.csv --truth truth.csv
//                       [--parameters params.json] [--profile drive-cycle|heat-cool|FILE]
//                       [--load-scale X] [--coolant loop|constant] [--no-coolant] [--no-winding-sensor]
//                       [--nominal] [--draw-electrical] [--set key=value]... [--exact] [--averaged]
// Exit codes: 0; 64 usage; 65 bad profile file; 73 an output cannot be written; 78 configuration.
#include <CLI/CLI.hpp>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "indep_thermal/errors.hpp"
#include "indep_thermal/generator.hpp"
#include "indep_thermal/writers.hpp"

namespace {

constexpr int kUsage = 64;
constexpr int kData = 65;
constexpr int kCantCreate = 73;
constexpr int kConfig = 78;

struct CantCreate : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void parse_set(indep_thermal::Parameters& p, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) throw indep_thermal::UsageError("--set " + assignment + ": expected key=value");
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size() || text.empty()) {
    throw indep_thermal::UsageError("--set " + assignment + ": '" + text + "' is not a number");
  }
  indep_thermal::set_parameter(p, key, value);
}

std::ofstream open_output(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw CantCreate(path + ": cannot be written");
  return out;
}

void close_output(std::ofstream& out, const std::string& path) {
  out.close();
  if (!out) throw CantCreate(path + ": write failed");
}

void list_parameters() {
  std::cout << "key,unit,draw,lo,hi,meaning\n";
  for (const auto& e : indep_thermal::catalogue()) {
    const char* draw = e.draw == indep_thermal::Draw::fixed     ? "fixed"
                       : e.draw == indep_thermal::Draw::factor  ? "factor"
                       : e.draw == indep_thermal::Draw::uniform ? "uniform"
                                                                : "electrical_factor";
    std::cout << e.key << ',' << e.unit << ',' << draw << ',' << indep_thermal::shortest(e.lo) << ','
              << indep_thermal::shortest(e.hi) << ",\"" << e.meaning << "\"\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Independent three-node thermal plant of a PMSM: a drive log and its thermal truth"};
  std::string config, out, truth, parameters_out, profile_name = "drive-cycle", coolant = "loop";
  std::uint64_t seed = 1;
  double duration_s = 7200.0, rate_Hz = 2.0, rtol = 1e-8, max_step_s = 0.25, load_scale = 1.0;
  std::size_t truth_every = 1;
  bool no_coolant = false, no_winding = false, nominal = false, draw_electrical = false, exact = false, averaged = false,
       list = false;
  std::vector<std::string> sets;
  app.add_option("--config", config, "configuration YAML (only machine: is read)");
  app.add_option("--seed", seed, "seed of the parameter draw, the drive cycle and the noise (default 1)");
  app.add_option("--duration-s", duration_s, "length [s] (default 7200)");
  app.add_option("--rate-Hz", rate_Hz, "row rate [Hz] (default 2)");
  app.add_option("--out", out, "drive log CSV");
  app.add_option("--truth", truth, "truth CSV (one row per log row)");
  app.add_option("--parameters", parameters_out, "parameters and summary JSON");
  app.add_option("--truth-every", truth_every, "write every N-th row to the truth CSV (default 1: all)")
      ->check(CLI::PositiveNumber);
  app.add_option("--profile", profile_name, "drive-cycle (default), heat-cool, or a CSV t_s,speed_rpm,i_q_A[,i_d_A]");
  app.add_option("--load-scale", load_scale, "multiplies the drive cycle's q currents (default 1)");
  app.add_option("--coolant", coolant, "loop (default: the coolant heats with the load) or constant")
      ->check(CLI::IsMember({"loop", "constant"}));
  app.add_flag("--no-coolant", no_coolant, "leave the T_coolant column out of the log");
  app.add_flag("--no-winding-sensor", no_winding, "leave the T_winding column out of the log");
  app.add_flag("--nominal", nominal, "the nominal plant (no draw)");
  app.add_flag("--draw-electrical", draw_electrical, "draw R_s, psi_m, L_d, L_q off the configuration too");
  app.add_option("--set", sets, "key=value for any parameter (repeatable; --list-parameters)");
  app.add_flag("--exact", exact, "no measurement noise and no quantisation in the log");
  app.add_flag("--averaged", averaged,
               "write the averaged log: t,t_start and window means over [t_k-1, t_k] (docs/drive-log.md)");
  app.add_option("--rtol", rtol, "relative tolerance of the integrator (default 1e-8)");
  app.add_option("--max-step-s", max_step_s, "largest integration step [s] (default 0.25)");
  app.add_flag("--list-parameters", list, "print the parameter catalogue and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kUsage;
  }
  if (list) {
    list_parameters();
    return 0;
  }
  try {
    if (config.empty() || out.empty() || truth.empty()) {
      throw indep_thermal::UsageError("--config, --out and --truth are required");
    }
    if (!(rtol > 0.0 && rtol < 1e-2)) throw indep_thermal::UsageError("--rtol must be in (0, 1e-2)");
    if (!(max_step_s > 0.0)) throw indep_thermal::UsageError("--max-step-s must be > 0");
    indep_thermal::Case c;
    c.machine = indep_thermal::read_machine(config);
    c.params = nominal ? indep_thermal::nominal_parameters(c.machine)
                       : indep_thermal::draw_parameters(c.machine, seed, {draw_electrical});
    for (const std::string& s : sets) parse_set(c.params, s);
    indep_thermal::validate(c.params);
    c.seed = seed;
    c.duration_s = duration_s;
    c.rate_Hz = rate_Hz;
    c.coolant = coolant == "loop" ? indep_thermal::CoolantMode::loop : indep_thermal::CoolantMode::constant;
    c.control.rtol = rtol;
    c.control.atol = rtol;
    c.control.max_step = max_step_s;
    c.noise = !exact;
    c.averaged = averaged;
    c.keep_rows = false;
    c.profile = indep_thermal::make_profile(profile_name, c.machine, duration_s, seed, load_scale);
    const indep_thermal::LogColumns columns{!no_coolant, !no_winding, averaged};
    std::ofstream log_file = open_output(out);
    std::ofstream truth_file = open_output(truth);
    indep_thermal::write_log_header(log_file, columns);
    indep_thermal::write_truth_header(truth_file);
    std::size_t row_index = 0;
    const indep_thermal::Result r = indep_thermal::generate(c, [&](const indep_thermal::Row& row) {
      indep_thermal::write_log_row(log_file, row, columns);
      if (row_index++ % truth_every == 0) indep_thermal::write_truth_row(truth_file, row);
    });
    close_output(log_file, out);
    close_output(truth_file, truth);
    if (!parameters_out.empty()) {
      std::ofstream json = open_output(parameters_out);
      json << indep_thermal::parameters_json(c, r, columns).dump(2) << '\n';
      close_output(json, parameters_out);
    }
    return 0;
  } catch (const indep_thermal::UsageError& e) {
    std::cerr << "indep_thermal_plant: " << e.what() << '\n';
    return kUsage;
  } catch (const indep_thermal::DataError& e) {
    std::cerr << "indep_thermal_plant: profile error: " << e.what() << '\n';
    return kData;
  } catch (const indep_thermal::ConfigError& e) {
    std::cerr << "indep_thermal_plant: configuration error: " << e.what() << '\n';
    return kConfig;
  } catch (const CantCreate& e) {
    std::cerr << "indep_thermal_plant: " << e.what() << '\n';
    return kCantCreate;
  }
}
