#include "indep_drive/truth.hpp"

#include <nlohmann/json.hpp>

#include <stdexcept>

#include "indep_drive/inverter.hpp"

namespace indep {

double EffectTruth::value(const std::string& key) const {
  for (const auto& [k, v] : values) {
    if (k == key) return v;
  }
  throw std::out_of_range(name + ": no value '" + key + "'");
}

const EffectTruth* Truth::effect(const std::string& n) const {
  for (const EffectTruth& e : effects) {
    if (e.name == n) return &e;
  }
  return nullptr;
}

namespace {

nlohmann::json machine_json(const MachineParams& m) {
  return {{"psi_m_Wb", m.psi_m_Wb},
          {"r_s_Ohm", m.r_s_Ohm},
          {"l_d_H", m.l_d_H},
          {"l_q_H", m.l_q_H},
          {"pole_pairs", m.pole_pairs}};
}

nlohmann::json track_json(const TemperatureTrack& t) {
  return {{"start_C", t.start_C}, {"end_C", t.end_C}, {"tau_s", t.tau_s}};
}

}  // namespace

std::string truth_json(const Truth& t) {
  nlohmann::json j;
  j["generator"] = "indep_drive_log (tests/independent_drive)";
  j["config"] = t.config_path;
  j["configured_machine"] = machine_json(t.configured);
  j["true_machine"] = machine_json(t.true_machine);
  j["true_over_configured"] = {{"psi_m", t.true_machine.psi_m_Wb / t.configured.psi_m_Wb},
                               {"r_s", t.true_machine.r_s_Ohm / t.configured.r_s_Ohm},
                               {"l_d", t.true_machine.l_d_H / t.configured.l_d_H},
                               {"l_q", t.true_machine.l_q_H / t.configured.l_q_H}};
  j["seed"] = t.seed;
  j["duration_s"] = t.duration_s;
  j["control_period_s"] = t.control_period_s;
  j["inverter"] = {{"u_dc_V", t.u_dc_V}, {"switching_frequency_Hz", t.switching_frequency_Hz}, {"modulation", t.modulation}};
  j["initial_theta_rad"] = t.initial_theta_rad;
  j["max_current_A"] = t.max_current_A;
  const SensorSettings& n = t.noise;
  j["noise"] = {{"current_noise_A", n.current_noise_A},
                {"adc_bits", n.adc_bits},
                {"adc_full_scale_A", n.adc_full_scale_A},
                {"adc_lsb_A", n.adc_bits > 0 ? 2.0 * n.adc_full_scale_A / std::ldexp(1.0, n.adc_bits) : 0.0},
                {"encoder_counts_per_rev", n.encoder_counts_per_rev},
                {"u_dc_noise_V", n.u_dc_noise_V},
                {"u_dc_adc_bits", n.u_dc_adc_bits},
                {"u_dc_full_scale_V", n.u_dc_full_scale_V},
                {"omega_noise_rad_s", n.omega_noise_rad_s},
                {"temperature_noise_K", n.temperature_noise_K}};
  j["temperatures"] = {{"winding", track_json(t.thermal.winding)}, {"magnet", track_json(t.thermal.magnet)}};
  nlohmann::json effects = nlohmann::json::object();
  nlohmann::json names = nlohmann::json::array();
  for (const EffectTruth& e : t.effects) {
    nlohmann::json one = {{"form", e.form}};
    for (const auto& [k, v] : e.values) one[k] = v;
    for (const auto& [k, v] : e.labels) one[k] = v;
    effects[e.name] = one;
    names.push_back(e.name);
  }
  j["effect_names"] = names;
  j["effects"] = effects;
  return j.dump(2) + "\n";
}

}  // namespace indep
