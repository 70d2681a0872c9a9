// indep_drive_log: writes a drive log from the independent generator (tests/independent_drive/README.md).
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "indep_drive/case.hpp"
#include "indep_drive/csv_writer.hpp"
#include "indep_drive/generator.hpp"

namespace {

constexpr int kExitUsage = 64;
constexpr int kExitData = 65;
constexpr int kExitConfig = 78;

/// The Beckhoff map beside the configuration's data folder (config/../data/...), if it is there.
std::string map_beside(const std::string& config) {
  const std::filesystem::path p = std::filesystem::path(config).parent_path() / ".." / "data" / "beckhoff-am8141-flux-maps" /
                                  "beckhoff_AM8141_measured_400rpm.csv";
  return std::filesystem::exists(p) ? p.lexically_normal().string() : std::string();
}

void apply_set(indep::Case& c, const std::string& assignment) {
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
  indep::set_parameter(c, key, value);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Independent drive-log generator: a closed-loop PMSM drive with hidden effects, written apart from "
      "rpem's simulator (tests/independent_drive/README.md)"};
  std::string config, effects = "none", out, truth_path, plant_out, profile, flux_map, modulation = "space_vector";
  std::string averaged_source = "plant";
  std::uint64_t seed = 1;
  double duration = 20.0, control_rate = 8000.0, averaged_rate = 200.0, jitter = 0.3;
  bool averaged = false, nominal = false, draw_effects = false, list_effects = false, list_parameters = false;
  std::vector<std::string> sets;
  app.add_option("--config", config, "configuration YAML (its machine section)");
  app.add_option("--effects", effects, "comma-separated effects to hide (--list-effects)");
  app.add_option("--seed", seed, "seed of every random draw");
  app.add_option("--duration-s", duration, "length of the log [s]");
  app.add_option("--control-rate-Hz", control_rate, "control and sampling rate [Hz]");
  app.add_option("--out", out, "drive-log CSV (with --averaged: the averaged rotor-frame CSV)");
  app.add_option("--truth", truth_path, "truth JSON");
  app.add_option("--plant-out", plant_out, "true plant state per control period (CSV)");
  app.add_flag("--averaged", averaged, "write averaged rotor-frame samples instead of the phase-frame log");
  app.add_option("--rate-Hz", averaged_rate, "mean rate of the averaged samples [Hz]");
  app.add_option("--jitter", jitter, "relative spread of the averaging intervals, [0, 1)");
  app.add_option("--averaged-source", averaged_source, "plant (true quantities) or drive (measured and commanded)");
  app.add_option("--profile", profile, "operating profile CSV t_s,speed_rpm,torque_Nm[,i_d_inject_A]");
  app.add_option("--flux-map", flux_map, "measured flux map for the saturation effects");
  app.add_option("--modulation", modulation, "sine, third_harmonic or space_vector");
  app.add_flag("--nominal", nominal, "true machine = configuration (no draw)");
  app.add_flag("--draw-effect-params", draw_effects, "draw the parameters of the hidden effects from the seed");
  app.add_option("--set", sets, "parameter override key=value (repeatable; --list-parameters)");
  app.add_flag("--list-effects", list_effects, "print the effect catalogue and exit");
  app.add_flag("--list-parameters", list_parameters, "print the parameter keys and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitUsage;
  }
  if (list_effects) {
    for (const indep::EffectEntry& e : indep::effect_catalogue()) std::printf("%-18s %s\n", e.name, e.what);
    return 0;
  }
  if (list_parameters) {
    for (const indep::ParameterEntry& p : indep::parameter_catalogue()) std::printf("%-34s [%s]\n", p.key, p.unit);
    return 0;
  }
  if (config.empty() || (out.empty() && truth_path.empty() && plant_out.empty())) {
    std::cerr << "indep_drive_log: --config and at least one of --out, --truth, --plant-out are required\n";
    return kExitUsage;
  }
  indep::Case c;
  try {
    c.machine = indep::read_machine_config(config);
  } catch (const indep::ConfigError& e) {
    std::cerr << "indep_drive_log: configuration error: " << e.what() << "\n";
    return kExitConfig;
  }
  try {
    c.seed = seed;
    c.duration_s = duration;
    c.control.rate_Hz = control_rate;
    indep::enable_effects(c.effects, effects);
    c.effects.saturation.map_path = flux_map.empty() ? map_beside(config) : flux_map;
    c.inverter.modulation = indep::modulation_from_name(modulation);
    if (nominal) c.draw.psi_m_rel = c.draw.r_s_rel = c.draw.l_d_rel = c.draw.l_q_rel = 0.0;
    c.averaged.on = averaged;
    c.averaged.rate_Hz = averaged_rate;
    c.averaged.jitter_rel = jitter;
    if (averaged_source != "plant" && averaged_source != "drive") {
      throw std::invalid_argument("--averaged-source: expected plant or drive");
    }
    c.averaged.source = averaged_source == "plant" ? indep::AveragedSource::plant : indep::AveragedSource::drive;
    c.keep_log_rows = !averaged;
    c.keep_plant_rows = !plant_out.empty();
    if (!profile.empty()) c.profile.points = indep::read_profile_csv(profile).points();
    for (const std::string& s : sets) apply_set(c, s);
    if (draw_effects) {
      indep::draw_effect_parameters(c);
      for (const std::string& s : sets) apply_set(c, s);  // what the user set explicitly wins over the draw
    }
    const auto start = std::chrono::steady_clock::now();
    const indep::Result r = indep::generate(c);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!out.empty()) indep::write_file(out, averaged ? indep::averaged_csv(r.averaged) : indep::log_csv(r.log));
    if (!truth_path.empty()) indep::write_file(truth_path, indep::truth_json(r.truth));
    if (!plant_out.empty()) indep::write_file(plant_out, indep::plant_csv(r.plant));
    std::string hidden;
    for (const std::string& name : indep::enabled_effects(c.effects)) hidden += (hidden.empty() ? "" : ",") + name;
    std::fprintf(stderr, "indep_drive_log: %.1f s at %.0f Hz generated in %.2f s (effects: %s)\n", c.duration_s,
                 c.control.rate_Hz, seconds, hidden.empty() ? "none" : hidden.c_str());
  } catch (const std::invalid_argument& e) {
    std::cerr << "indep_drive_log: " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::runtime_error& e) {
    std::cerr << "indep_drive_log: " << e.what() << "\n";
    return kExitData;
  }
  return 0;
}
