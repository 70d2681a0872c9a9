#include "rpem/core/settings.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::core {

MachinePu to_pu(const PerUnitBase& base, const MachineSi& m) noexcept {
  return {base.resistance_pu(m.r_s_Ohm), base.inductance_pu(m.l_d_H), base.inductance_pu(m.l_q_H), base.flux_pu(m.psi_m_Wb)};
}

EstimatorConfig make_estimator_config(const PerUnitBase& base, const MachineSi& m, const EstimatorSettings& s) noexcept {
  EstimatorConfig c;
  static_cast<EstimatorOptions&>(c) = s;
  c.model = to_pu(base, m);
  c.omega_n_rad_s = base.omega_el_rad_s;
  c.scheduler.psi_m_min_speed_pu = base.mech_speed_rpm_to_pu(s.psi_m_min_speed_rpm);
  c.scheduler.r_s_max_speed_pu = base.mech_speed_rpm_to_pu(s.r_s_max_speed_rpm);
  c.bounds.min_pu = {base.flux_pu(s.psi_m_min_Wb), base.resistance_pu(s.r_s_min_Ohm)};
  c.bounds.max_pu = {base.flux_pu(s.psi_m_max_Wb), base.resistance_pu(s.r_s_max_Ohm)};
  c.initial_theta_pu = {base.flux_pu(s.initial_psi_m_Wb), base.resistance_pu(s.initial_r_s_Ohm)};
  return c;
}

std::array<GainSequences, 3> averaged_rates_per_s(const EstimatorSettings& s) noexcept {
  std::array<GainSequences, 3> rates{};
  const double per_s = 1.0 / s.nominal_sample_period_s;
  for (std::size_t a = 0; a < rates.size(); ++a) {
    if (s.averaged.rates_given[a]) {
      rates[a] = s.averaged.rates_per_s[a];
    } else {
      rates[a] = {s.gains[a].hessian * per_s, s.gains[a].gain * per_s};
    }
  }
  return rates;
}

EstimatorSettings for_applied_voltages(EstimatorSettings s) noexcept {
  s.averaged.voltage_is_command = false;
  s.extensions.delay_s = 0.0;
  return s;
}

RegimeConfig make_regime_config(const PerUnitBase& base, const MachineSi& m, const EstimatorSettings& s) noexcept {
  const RegimeSettings& g = s.regimes;
  RegimeConfig c;
  c.z = g.significance_sigma;
  c.chi2 = chi2_bound(g.significance_sigma);
  c.omega_n_rad_s = base.omega_el_rad_s;
  const MachinePu nominal = to_pu(base, m);
  c.r_pu = nominal.r_s_pu;
  c.r_min_pu = base.resistance_pu(s.r_s_min_Ohm);
  c.dr_pu = std::max(c.r_pu - c.r_min_pu, base.resistance_pu(s.r_s_max_Ohm) - c.r_pu);
  c.psi_min_pu = base.flux_pu(s.psi_m_min_Wb);
  c.psi_max_pu = base.flux_pu(s.psi_m_max_Wb);
  c.dpsi_pu = std::max(nominal.psi_m_pu - c.psi_min_pu, c.psi_max_pu - nominal.psi_m_pu);
  c.x_d_pu = nominal.x_d_pu;
  c.x_q_pu = nominal.x_q_pu;
  c.dx_d_pu = g.inductance_tolerance * nominal.x_d_pu;
  c.dx_q_pu = g.inductance_tolerance * nominal.x_q_pu;
  c.tan_angle = std::tan(g.angle_tolerance_rad);
  c.sensorless = g.sensorless;
  c.hall_frame_error_rad = g.sensorless ? g.hall_frame_error_rad : 0.0;
  c.hall_below_n_pu = c.hall_frame_error_rad > 0.0 ? base.speed_pu(g.hall_below_speed_rad_s) : 0.0;
  c.angle_source_assumed = g.angle_source_assumed && !g.sensorless;
  c.resolution_pu = {base.voltage_pu(g.voltage_resolution_V), base.current_pu(g.current_resolution_A),
                     base.speed_pu(g.speed_resolution_rad_s)};
  // The slowest decay of Eq_FullOrderModel: Re λ ≥ −ω_n·r/x per axis, slowest with D_M's smallest r_s.
  c.electrical_time_constant_s = std::max(nominal.x_d_pu, nominal.x_q_pu) / (base.omega_el_rad_s * c.r_min_pu);
  // A control-rate stream is classified a block at a time: a change of regime reaches the adaptation at most
  // a block late, and the samples of one block carry N·γ_L ≤ 1 % of the estimate (§13, "Control-rate streams").
  const double gamma = s.gains[static_cast<std::size_t>(s.algorithm)].gain.maxCoeff();
  c.stream_block = gamma > 0.0 ? static_cast<int>(std::clamp(std::floor(0.01 / gamma), 1.0, 64.0)) : 64;
  return c;
}

}  // namespace rpem::core
