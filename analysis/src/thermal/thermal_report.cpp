#include "rpem/analysis/thermal/thermal_report.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rpem/io/errors.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::analysis {
namespace {

std::ofstream open(const std::string& path) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw io::InputError(path, 0, 0, "", "cannot create file");
  return f;
}

/// v with `digits` significant digits.
std::string significant(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

/// A temperature as text, to the 0.1 K a sensor is read to.
std::string celsius(double v_C) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f", v_C);
  return buf;
}

/// A relative half-width as an interval's text; beyond ±1000 % the log does not bound the parameter at all.
std::string interval(double rel) {
  if (!std::isfinite(rel)) return "not excited";
  return rel > 10.0 ? std::string("unbounded (> ±1000 %)") : "±" + significant(100.0 * rel) + " %";
}

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

std::string training_span(const SignalFit& s) {
  if (!std::isfinite(s.training_low_C)) return "none";
  return celsius(s.training_low_C) + "–" + celsius(s.training_high_C) + " °C";
}

void write_thermal_yaml(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record,
                        const std::string& config_name) {
  std::ofstream f = open(path);
  f << "# Thermal network fitted by `rpem thermal fit` (docs/thermal.md)\n";
  f << "# log: " << record.log << " (" << record.steps.size() << " steps), configuration: " << config_name << "\n";
  if (record.session_first_step.size() > 1) {
    f << "# sessions, one after another on the fit's time axis:";
    for (const std::string& log : record.session_logs) f << " " << log;
    f << "\n";
  }
  f << "# training: t <= " << fit.fit_until_s << " s (" << fit.training_steps << " steps); the rest held out\n";
  for (const SignalFit& s : fit.signals) {
    // A part without points has no figure (not one of 0 K).
    f << "# " << s.name << ": " << training_span(s) << " in training (5–95 %, σ " << significant(s.training_sigma_K)
      << " K); ";
    if (s.fit_points > 0) f << "fit " << significant(s.fit_rms_K) << " K RMS (" << s.fit_points << "), ";
    if (s.heldout_points > 0) {
      f << "held out " << significant(s.heldout_rms_K) << " K RMS, worst " << significant(s.heldout_worst_K) << " K ("
        << s.heldout_points << ")\n";
    } else {
      f << "nothing held out\n";
    }
  }
  for (const FittedParameter& p : fit.parameters) {
    if (!p.identified) f << "# not identified: " << p.name << " (95 % interval " << interval(p.half_width_rel) << ")\n";
  }
  for (const std::string& s : fit.not_identifiable) f << "# move together: " << s << "\n";
  for (const std::string& s : fit.notes) f << "# note: " << s << "\n";
  f << io::thermal_config_yaml(fit.config);
}

void write_thermal_fit_json(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record,
                            const std::string& config_name) {
  nlohmann::json j;
  j["log"] = record.log;
  j["configuration"] = config_name;
  j["steps"] = record.steps.size();
  j["sessions"] = nlohmann::json::array();
  for (std::size_t k = 0; k < record.session_first_step.size(); ++k) {
    const std::size_t first = record.session_first_step[k];
    j["sessions"].push_back({{"log", record.session_logs[k]}, {"first_step", first}, {"t_first_s", record.t_s[first]}});
  }
  j["fit_until_s"] = fit.fit_until_s;
  j["training_steps"] = fit.training_steps;
  j["training_cost"] = fit.training_cost;
  j["process_noise_K2_per_s"] = fit.process_noise_K2_per_s;
  j["disturbance_W2_per_s"] = fit.disturbance_W2_per_s;
  // τ_d per node in use; +∞ (the random walk) is written as null.
  for (int i = 0; i < fit.config.fusion.filter.network.nodes; ++i)
    j["disturbance_time_constant_s"].push_back(fit.disturbance_time_constant_s[i]);
  j["disturbance_time_constant_threshold"] = fit.disturbance_time_constant_threshold;
  j["coolant_drift_K2_per_s"] = fit.coolant_drift.q_K2_per_s;
  j["coolant_drift_at_lag_s"] = fit.coolant_drift.at_lag_s;
  j["coolant_reading_floor_K2"] = fit.coolant_drift.floor_K2;
  for (const ThermalFitResult::TimeConstantTrial& t : fit.disturbance_time_constant_log_likelihood) {
    j["disturbance_time_constant_grid"].push_back(
        {{"node", t.node}, {"time_constant_s", t.time_constant_s}, {"log_likelihood", t.log_likelihood}});
  }
  for (const FittedParameter& p : fit.parameters) {
    j["parameters"].push_back({{"name", p.name},
                               {"unit", p.unit},
                               {"value", p.value},
                               {"half_width_rel", number_or_null(p.half_width_rel)},
                               {"excitation_half_width_rel", number_or_null(p.excitation_half_width_rel)},
                               {"identified", p.identified}});
  }
  for (const SignalFit& s : fit.signals) {
    j["signals"].push_back({{"name", s.name},
                            {"fit_points", s.fit_points},
                            {"fit_rms_K", s.fit_rms_K},
                            {"heldout_points", s.heldout_points},
                            {"heldout_rms_K", s.heldout_rms_K},
                            {"heldout_worst_K", s.heldout_worst_K},
                            {"training_low_C", number_or_null(s.training_low_C)},
                            {"training_high_C", number_or_null(s.training_high_C)},
                            {"training_sigma_K", s.training_sigma_K}});
  }
  j["not_identifiable"] = fit.not_identifiable;
  j["notes"] = fit.notes;
  std::ofstream f = open(path);
  f << j.dump(2) << "\n";
}

void write_thermal_fit_report(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record,
                              const std::string& config_name) {
  std::ostringstream o;
  o << "# Thermal network fit\n\n";
  o << "Log `" << record.log << "` (" << record.steps.size() << " steps of the filter), configuration `" << config_name
    << "`. Training: the steps up to t = " << fit.fit_until_s << " s (" << fit.training_steps
    << "); the rest is held out. The network runs open loop from a soaked start (every node at the coolant)"
    << (record.session_first_step.size() > 1 ? ", each session from its own" : "") << ".\n\n";
  if (record.session_first_step.size() > 1) {
    o << "Sessions, one after another on the fit's time axis `t` (each from its own start; predictions.csv's "
         "`session`):\n\n| session | log | steps | t from [s] |\n|---|---|---|---|\n";
    for (std::size_t k = 0; k < record.session_first_step.size(); ++k) {
      const std::size_t first = record.session_first_step[k];
      o << "| " << k << " | `" << record.session_logs[k] << "` | " << record.session_end(k) - first << " | "
        << significant(record.t_s[first], 6) << " |\n";
    }
    o << "\n";
  }
  o << "| signal | observed in training, 5–95 % | σ [K] | fit RMS [K] | points | held-out RMS [K] | held-out worst "
       "[K] | points |\n|---|---|---|---|---|---|---|---|\n";
  // A part without points has no figure: "—", not 0 K.
  const auto figure = [](double k, std::size_t points) { return points > 0 ? significant(k) : std::string("—"); };
  for (const SignalFit& s : fit.signals) {
    o << "| " << s.name << " | " << training_span(s) << " | " << significant(s.training_sigma_K) << " | "
      << figure(s.fit_rms_K, s.fit_points) << " | " << s.fit_points << " | " << figure(s.heldout_rms_K, s.heldout_points)
      << " | " << figure(s.heldout_worst_K, s.heldout_points) << " | " << s.heldout_points << " |\n";
  }
  o << "\n## Parameters (95 % intervals: cluster-robust over "
    << "blocks of the training part; excitation alone)\n\n";
  o << "| parameter | value | unit | robust | excitation | identified |\n|---|---|---|---|---|---|\n";
  for (const FittedParameter& p : fit.parameters) {
    o << "| " << p.name << " | " << significant(p.value, 5) << " | " << p.unit << " | " << interval(p.half_width_rel)
      << " | " << interval(p.excitation_half_width_rel) << " | " << (p.identified ? "yes" : "**no**") << " |\n";
  }
  o << "\nProcess noise (maximum likelihood of the filter's innovations over the training part): "
    << significant(fit.process_noise_K2_per_s) << " K²/s per node; the heat disturbances' drift "
    << significant(fit.disturbance_W2_per_s) << " W²/s per node; their correlation times (eq. 14.19)";
  for (int i = 0; i < fit.config.fusion.filter.network.nodes; ++i) {
    const double tau = fit.disturbance_time_constant_s[i];
    o << (i ? ", " : " ") << fit.config.node_names[static_cast<std::size_t>(i)] << " "
      << (std::isfinite(tau) ? significant(tau) + " s" : "∞ (a random walk)");
  }
  o << " (a finite one kept only where it gains more than " << significant(fit.disturbance_time_constant_threshold)
    << " in log-likelihood over the walk: the likelihood-ratio test at 5 % over the grid, eq. 14.21a).\n";
  o << "\n" << coolant_drift_sentence(fit.coolant_drift) << "\n";
  if (!fit.not_identifiable.empty()) {
    o << "\n## Not identifiable\n\nParameters the log cannot tell apart (they move together along a direction the "
         "residuals barely change):\n\n";
    for (const std::string& s : fit.not_identifiable) o << "- " << s << "\n";
  }
  if (!fit.notes.empty()) {
    o << "\n## Notes\n\n";
    for (const std::string& s : fit.notes) o << "- " << s << "\n";
  }
  std::ofstream f = open(path);
  f << o.str();
}

void write_thermal_predictions(const std::string& path, const ThermalFitResult& fit, const ThermalRecord& record) {
  std::ofstream f = open(path);
  const io::ThermalConfig& c = fit.config;
  const core::ThermalNetwork& n = c.fusion.filter.network;
  f << "t";
  for (int i = 0; i < n.nodes; ++i) f << ",T_" << c.node_names[static_cast<std::size_t>(i)] << "_model";
  f << ",T_magnet_observed,T_winding_observed,T_winding_sensor,T_coolant,copper_loss_W,session\n";
  std::string line;
  std::size_t session = 0;
  for (std::size_t k = 0; k < record.steps.size(); ++k) {
    if (k > 0 && record.starts_session(k)) ++session;
    const core::ThermalStepData& s = record.steps[k];
    line.clear();
    io::append_number(line, record.t_s[k]);
    for (int i = 0; i < n.nodes; ++i) io::append_number(line += ',', fit.open_loop_C[k][i]);
    const core::ParameterObservation& pm = s.parameter[core::kPsiM];
    const core::ParameterObservation& pr = s.parameter[core::kRs];
    line += ',';
    if (pm.valid) io::append_number(line, c.fusion.magnet_law.temperature_C(pm.value));
    line += ',';
    if (pr.valid) io::append_number(line, n.copper.temperature_C(pr.value));
    line += ',';
    if (std::isfinite(s.winding_sensor_C)) io::append_number(line, s.winding_sensor_C);
    io::append_number(line += ',', s.load.coolant_C);
    io::append_number(line += ',', 1.5 * s.load.current_sq_A2 * n.copper.at(fit.open_loop_C[k][n.winding]));
    f << line << ',' << session << '\n';
  }
}

}  // namespace rpem::analysis
