#include "indep_thermal/writers.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "indep_thermal/convection.hpp"
#include "indep_thermal/network.hpp"

namespace indep_thermal {

std::string shortest(double x) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, x);
  return ec == std::errc() ? std::string(buf, ptr) : std::string("nan");
}

namespace {

void write_row(std::ostream& out, const std::vector<double>& values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out << ',';
    out << shortest(values[i]);
  }
  out << '\n';
}

void write_header(std::ostream& out, const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < names.size(); ++i) out << (i > 0 ? "," : "") << names[i];
  out << '\n';
}

// Time constants 1/λ of C·dT/dt = −G·T at a speed: λ the eigenvalues of C^−½·G·C^−½ (symmetric) [s].
std::vector<double> time_constants_s(const Parameters& p, double omega_mech) {
  const Eigen::Vector3d c = capacities(p);
  const Eigen::Vector3d s = c.cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d m = s.asDiagonal() * conductances(p, omega_mech).matrix() * s.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  std::vector<double> tau;
  for (int i = 0; i < 3; ++i) tau.push_back(1.0 / eig.eigenvalues()(i));
  std::sort(tau.begin(), tau.end());
  return tau;
}

nlohmann::json conductances_json(const Conductances& g) {
  return {{"winding_iron", g.winding_iron},   {"iron_coolant", g.iron_coolant},       {"airgap", g.airgap},
          {"winding_rotor", g.winding_rotor}, {"winding_coolant", g.winding_coolant}, {"rotor_coolant", g.rotor_coolant}};
}

nlohmann::json parameter_values(const Parameters& p) {
  nlohmann::json j = nlohmann::json::object();
  for (const CatalogueEntry& e : catalogue()) j[e.key] = p.*e.field;
  return j;
}

}  // namespace

std::vector<std::string> log_header(LogColumns columns) {
  std::vector<std::string> h = {"t"};
  if (columns.averaged) h.emplace_back("t_start");
  for (const char* name : {"i_d", "i_q", "u_d", "u_q", "omega_el"}) h.emplace_back(name);
  if (columns.coolant) h.emplace_back("T_coolant");
  if (columns.winding_sensor) h.emplace_back("T_winding");
  return h;
}

const std::vector<std::string>& truth_header() {
  static const std::vector<std::string> h = {"t",
                                             "T_winding",
                                             "T_iron",
                                             "T_magnet",
                                             "T_coolant",
                                             "T_winding_sensor",
                                             "r_s",
                                             "r_s_ac",
                                             "psi_m",
                                             "omega_el",
                                             "speed_rpm",
                                             "i_d",
                                             "i_q",
                                             "u_d",
                                             "u_q",
                                             "flux_rel",
                                             "P_copper",
                                             "P_stator_hysteresis",
                                             "P_stator_eddy",
                                             "P_stator_excess",
                                             "P_rotor_iron",
                                             "P_magnet",
                                             "P_mechanical",
                                             "P_winding",
                                             "P_iron",
                                             "P_rotor",
                                             "P_total",
                                             "Q_coolant",
                                             "G_winding_iron",
                                             "G_iron_coolant",
                                             "G_airgap",
                                             "G_winding_rotor",
                                             "G_winding_coolant",
                                             "G_rotor_coolant",
                                             "E_losses",
                                             "E_coolant",
                                             "E_stored",
                                             "E_residual",
                                             "t_start",
                                             "i_d_mean",
                                             "i_q_mean",
                                             "u_d_mean",
                                             "u_q_mean",
                                             "omega_el_mean"};
  return h;
}

void write_log_header(std::ostream& out, LogColumns columns) { write_header(out, log_header(columns)); }

void write_log_row(std::ostream& out, const Row& r, LogColumns columns) {
  std::vector<double> v = {r.truth.t_s};
  if (columns.averaged) v.push_back(r.t_start_s);
  v.insert(v.end(), {r.i_d_A, r.i_q_A, r.u_d_V, r.u_q_V, r.omega_el_rad_s});
  if (columns.coolant) v.push_back(r.t_coolant_C);
  if (columns.winding_sensor) v.push_back(r.t_winding_C);
  write_row(out, v);
}

void write_truth_header(std::ostream& out) { write_header(out, truth_header()); }

void write_truth_row(std::ostream& out, const Row& r) {
  const Snapshot& s = r.truth;
  const Losses& l = s.losses;
  const double e_losses = s.y(kEWinding) + s.y(kEIron) + s.y(kERotor);
  write_row(out, {s.t_s,
                  s.y(kTWinding),
                  s.y(kTIron),
                  s.y(kTRotor),
                  s.y(kTCoolant),
                  s.sensor_reading_C,
                  s.r_s_dc_Ohm,
                  s.r_s_ac_Ohm,
                  s.psi_m_Wb,
                  s.op.omega_el_rad_s,
                  s.speed_rpm,
                  s.op.i_d_A,
                  s.op.i_q_A,
                  s.u.u_d_V,
                  s.u.u_q_V,
                  l.flux_rel,
                  l.copper,
                  l.stator_hysteresis,
                  l.stator_eddy,
                  l.stator_excess,
                  l.rotor_iron,
                  l.magnet,
                  l.mechanical,
                  l.winding(),
                  l.iron(),
                  l.rotor(),
                  l.total(),
                  s.heat_to_coolant_W,
                  s.g.winding_iron,
                  s.g.iron_coolant,
                  s.g.airgap,
                  s.g.winding_rotor,
                  s.g.winding_coolant,
                  s.g.rotor_coolant,
                  e_losses,
                  s.y(kECoolant),
                  r.stored_J,
                  r.residual_J,
                  r.t_start_s,
                  r.i_d_mean_A,
                  r.i_q_mean_A,
                  r.u_d_mean_V,
                  r.u_q_mean_V,
                  r.omega_el_mean_rad_s});
}

void write_log_csv(std::ostream& out, const Result& result, LogColumns columns) {
  write_log_header(out, columns);
  for (const Row& r : result.rows) write_log_row(out, r, columns);
}

void write_truth_csv(std::ostream& out, const Result& result) {
  write_truth_header(out);
  for (const Row& r : result.rows) write_truth_row(out, r);
}

nlohmann::json parameters_json(const Case& c, const Result& result, LogColumns columns) {
  const Parameters& p = c.params;
  nlohmann::json j;
  j["generator"] = "indep_thermal_plant";
  j["seed"] = c.seed;
  j["config"] = c.machine.source;
  j["profile"] = c.profile.name;
  j["coolant_mode"] = c.coolant == CoolantMode::loop ? "loop" : "constant";
  j["duration_s"] = c.duration_s;
  j["rate_Hz"] = c.rate_Hz;
  j["rows"] = result.summary.rows;
  j["noise"] = c.noise;
  j["averaged"] = c.averaged;
  j["log_columns"] = log_header(columns);
  j["truth_columns"] = truth_header();
  j["configured_machine"] = {{"r_s_Ohm", c.machine.r_s_Ohm},
                             {"psi_m_Wb", c.machine.psi_m_Wb},
                             {"l_d_H", c.machine.l_d_H},
                             {"l_q_H", c.machine.l_q_H},
                             {"pole_pairs", c.machine.pole_pairs},
                             {"voltage_ll_rms_V", c.machine.voltage_ll_rms_V},
                             {"current_rms_A", c.machine.current_rms_A},
                             {"speed_rpm", c.machine.speed_rpm},
                             {"rated_torque_Nm", c.machine.rated_torque_Nm()},
                             {"rated_power_W", c.machine.rated_power_W()}};
  j["parameters"] = parameter_values(p);
  j["nominal_parameters"] = parameter_values(nominal_parameters(c.machine));
  nlohmann::json units = nlohmann::json::object();
  for (const CatalogueEntry& e : catalogue()) units[e.key] = e.unit;
  j["units"] = units;

  const double w_n = p.rated_speed_rad_s;
  const EndSpaceAreas a = endspace_areas(p);
  j["derived"] = {{"copper_inferred_zero_C", -(1.0 / p.copper_alpha20_per_K - 20.0)},
                  {"rated_copper_loss_W", rated_copper_loss_W(p)},
                  {"taylor_number_at_rated_speed", taylor_number(p, w_n)},
                  {"endspace_areas_m2", {{"winding", a.winding_m2}, {"rotor", a.rotor_m2}, {"caps", a.caps_m2}}},
                  {"conductances_W_K_at_standstill", conductances_json(conductances(p, 0.0))},
                  {"conductances_W_K_at_rated_speed", conductances_json(conductances(p, w_n))},
                  {"time_constants_s_at_standstill", time_constants_s(p, 0.0)},
                  {"time_constants_s_at_rated_speed", time_constants_s(p, w_n)}};
  j["laws"] = {
      {"r_s",
       "R_s(T_w) = r_s_ref*(K + T_w)/(K + r_s_reference_C), K = 1/alpha20_copper - 20 degC (DC; the "
       "log's voltages use R_s*(1 + k_ac*(f/f_n)^2))"},
      {"psi_m", "psi_m(T_m) = psi_m_ref*(1 + alpha20_magnet*(T_m - 20))/(1 + alpha20_magnet*(psi_m_reference_C - 20))"},
      {"voltages", "steady state: u_d = R*i_d - w*L_q*i_q, u_q = R*i_q + w*(L_d*i_d + psi_m)"},
      {"magnet_temperature", "T_magnet is the rotor node (rotor iron, magnets, shaft)"}};

  const Summary& sum = result.summary;
  j["summary"] = {{"T_winding_max_C", sum.t_winding_max_C},
                  {"T_iron_max_C", sum.t_iron_max_C},
                  {"T_magnet_max_C", sum.t_magnet_max_C},
                  {"T_coolant_min_C", sum.t_coolant_min_C},
                  {"T_coolant_max_C", sum.t_coolant_max_C},
                  {"E_losses_J", sum.e_losses_J},
                  {"E_coolant_J", sum.e_coolant_J},
                  {"energy_residual_max_abs_J", sum.max_abs_residual_J},
                  {"integrator_steps_accepted", result.stats.accepted},
                  {"integrator_steps_rejected", result.stats.rejected},
                  {"integrator_evaluations", result.stats.evaluations}};
  return j;
}

}  // namespace indep_thermal
