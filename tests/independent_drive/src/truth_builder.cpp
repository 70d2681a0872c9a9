#include "truth_builder.hpp"

#include <cmath>
#include <complex>

#include "indep_drive/controller.hpp"
#include "indep_drive/flux_map.hpp"

namespace indep::detail {

void CurrentExtremes::update(Vec2 i) {
  if (std::abs(i.x) > std::abs(at_max_abs_d.x)) at_max_abs_d = i;
  if (std::abs(i.y) > std::abs(at_max_abs_q.y)) at_max_abs_q = i;
  if (i.norm() > at_max_norm.norm()) at_max_norm = i;
}

namespace {

const char* phase_name(int phase) { return phase == 0 ? "a" : phase == 1 ? "b" : "c"; }

EffectTruth deadtime(const Case& c) {
  const DeadTimeParams& d = c.effects.deadtime;
  const double per_leg = d.t_dead_s * c.inverter.switching_frequency_Hz * c.inverter.u_dc_V + d.v_device_V;
  return {"deadtime",
          "per leg e = -(t_dead*f_sw*u_dc + v_device)*tanh(i/i_band), added to the leg's average voltage",
          {{"t_dead_s", d.t_dead_s},
           {"switching_frequency_Hz", c.inverter.switching_frequency_Hz},
           {"u_dc_V", c.inverter.u_dc_V},
           {"v_device_V", d.v_device_V},
           {"i_band_A", d.i_band_A},
           {"per_leg_amplitude_V", per_leg},
           {"dq_fundamental_amplitude_V", 4.0 / kPi * per_leg}},
          {}};
}

EffectTruth delay(const Case& c) {
  const DelayParams& d = c.effects.delay;
  return {"delay",
          "the duties issued at t_k act from t_k + delay_s (the logged command is what was issued at t_k)",
          {{"delay_s", d.delay_s},
           {"delay_periods", d.periods},
           {"whole_periods", std::floor(d.periods)},
           {"fraction", d.periods - std::floor(d.periods)}},
          {}};
}

EffectTruth theta_offset(const Case& c) {
  const double o = c.effects.theta_offset.offset_rad;
  return {"theta_offset",
          "theta_true = theta_logged + offset_rad (the encoder reads offset_rad behind), before quantisation",
          {{"offset_rad", o}, {"offset_deg", o * 180.0 / kPi}, {"logged_minus_true_rad", -o}},
          {}};
}

/// Per-phase keys `<prefix>_a<unit>`…, `phase` naming the phases that differ from `neutral`, and the first
/// of them under `key` (with `gain_error` for gains) so a single-phase error reads as one number.
EffectTruth phase_errors(const char* name, const char* form, const PhaseErrorParams& p, double neutral, const char* prefix,
                         const char* unit, const char* key) {
  EffectTruth t{name, form, {}, {}};
  std::string phases;
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string phase = phase_name(static_cast<int>(k));
    t.values.emplace_back(std::string(prefix) + "_" + phase + unit, p.value[k]);
    if (p.value[k] == neutral) continue;
    if (phases.empty()) {
      t.values.emplace_back(key, p.value[k]);
      if (neutral == 1.0) t.values.emplace_back("gain_error", p.value[k] - 1.0);
    }
    phases += (phases.empty() ? "" : ",") + phase;
  }
  t.labels.emplace_back("phase", phases);
  return t;
}

EffectTruth current_offset(const Case& c) {
  return phase_errors("current_offset", "i_measured = i_true + offset per phase, before noise and quantisation",
                      c.effects.current_offset, 0.0, "offset", "_A", "offset_A");
}

EffectTruth current_gain(const Case& c) {
  return phase_errors("current_gain", "i_measured = gain * i_true per phase, before noise and quantisation",
                      c.effects.current_gain, 1.0, "gain", "", "gain");
}

/// The saturation effects, each evaluated with its own terms only, at the log's largest currents.
std::vector<EffectTruth> saturation(const Case& c, const RunFacts& f) {
  std::vector<EffectTruth> out;
  const SaturationParams& s = c.effects.saturation;
  const MachineParams& m = f.true_machine;
  auto model = [&](SaturationParts parts) {
    parts.depth = s.depth;
    return scale_flux_map(*f.fit, m, s.full_scale_current_A, parts);
  };
  auto common = [&](EffectTruth& t) {
    t.values.insert(t.values.end(),
                    {{"full_scale_current_A", s.full_scale_current_A},
                     {"depth", s.depth},
                     {"map_fit_rms_Wb", f.fit->rms_residual_Wb},
                     {"map_axis_rotation_rad", f.fit->axis_rotation_rad},
                     {"largest_current_over_full_scale", f.extremes.at_max_norm.norm() / s.full_scale_current_A}});
    t.labels.push_back({"map", s.map_path});
  };
  if (s.ld) {
    const FluxModel fm = model({true, false, false});
    const double i = f.extremes.at_max_abs_d.x;
    const double apparent = std::abs(i) > 0 ? (fm.flux({i, 0}, m.psi_m_Wb).x - m.psi_m_Wb) / (i * m.l_d_H) : 1.0;
    EffectTruth t{"ld_saturation",
                  "psi_d gains the map's pure-d terms (scaled co-energy polynomial); L_d depends on i_d",
                  {{"at_i_d_A", i}, {"l_dd_ratio", fm.inductance({i, 0}).dd_H / m.l_d_H}, {"l_d_apparent_ratio", apparent}},
                  {}};
    common(t);
    out.push_back(t);
  }
  if (s.lq) {
    const FluxModel fm = model({false, true, false});
    const double i = f.extremes.at_max_abs_q.y;
    const double apparent = std::abs(i) > 0 ? fm.flux({0, i}, m.psi_m_Wb).y / (i * m.l_q_H) : 1.0;
    EffectTruth t{"lq_saturation",
                  "psi_q gains the map's pure-q terms (scaled co-energy polynomial); L_q depends on i_q",
                  {{"at_i_q_A", i}, {"l_qq_ratio", fm.inductance({0, i}).qq_H / m.l_q_H}, {"l_q_apparent_ratio", apparent}},
                  {}};
    common(t);
    out.push_back(t);
  }
  if (s.cross) {
    const FluxModel fm = model({false, false, true});
    const FluxModel linear(m.l_d_H, m.l_q_H, s.full_scale_current_A, {});
    const Vec2 i = f.extremes.at_max_norm;
    const Inductance2 l = fm.inductance(i);
    const Vec2 psi = fm.flux(i, m.psi_m_Wb), psi_lin = linear.flux(i, m.psi_m_Wb);
    EffectTruth t{"cross_saturation",
                  "mixed terms of the map's co-energy polynomial: psi_d against i_q and psi_q against i_d (reciprocal)",
                  {{"at_i_d_A", i.x},
                   {"at_i_q_A", i.y},
                   {"l_dq_H", l.dq_H},
                   {"l_dq_over_sqrt_ld_lq", l.dq_H / std::sqrt(m.l_d_H * m.l_q_H)},
                   {"psi_d_change_rel", (psi.x - psi_lin.x) / m.psi_m_Wb},
                   {"l_q_apparent_ratio", std::abs(i.y) > 0 ? psi.y / psi_lin.y : 1.0},
                   {"l_dd_ratio", l.dd_H / m.l_d_H},
                   {"l_qq_ratio", l.qq_H / m.l_q_H}},
                  {}};
    common(t);
    out.push_back(t);
  }
  return out;
}

EffectTruth harmonic(const char* name, const HarmonicPair& h) {
  using C = std::complex<double>;
  const C lo = std::polar(h.h_lo_rel, -h.phi_lo_rad), hi = std::polar(h.h_hi_rel, h.phi_hi_rad);
  const C cd = lo + hi, cq = C(0, 1) * (lo - hi);
  const std::string n = std::to_string(h.order - 1), n2 = std::to_string(h.order + 1);
  return {name,
          "rotor-frame flux += psi_m*(h_lo*e^{j(phi_lo - n*theta)} + h_hi*e^{j(phi_hi + n*theta)}); components "
          "psi_d,h = psi_m*d_amplitude_rel*cos(n*theta + d_phase_rad), psi_q,h likewise, theta the true electrical angle",
          {{"order", h.order},
           {"d_amplitude_rel", std::abs(cd)},
           {"d_phase_rad", std::arg(cd)},
           {"q_amplitude_rel", std::abs(cq)},
           {"q_phase_rad", std::arg(cq)},
           {"h" + n + "_rel", h.h_lo_rel},
           {"h" + n + "_phase_rad", h.phi_lo_rad},
           {"h" + n2 + "_rel", h.h_hi_rel},
           {"h" + n2 + "_phase_rad", h.phi_hi_rad},
           {"back_emf_" + n + "_rel", (h.order - 1) * h.h_lo_rel},
           {"back_emf_" + n2 + "_rel", (h.order + 1) * h.h_hi_rel}},
          {}};
}

EffectTruth iron_loss(const Case& c, const RunFacts& f) {
  const double r = c.effects.iron_loss.r_fe_Ohm;
  const double e = c.machine.rated_omega_el_rad_s() * f.true_machine.psi_m_Wb;
  return {"iron_loss",
          "a resistance r_fe_Ohm across the induced voltage dpsi/dt + omega*J*psi (rotor frame)",
          {{"r_fe_Ohm", r}, {"loss_W_at_rated_speed_no_load", 1.5 * e * e / r}},
          {}};
}

EffectTruth drift(const char* name, const char* form, const DriftParams& d, const TemperatureTrack& track, double value0,
                  double duration) {
  const double start = track.at(0.0), end = track.at(duration);
  return {name,
          form,
          {{"coeff_per_K", d.coeff_per_K},
           {"reference_C", d.reference_C},
           {"temperature_start_C", start},
           {"temperature_end_C", end},
           {"temperature_span_K", std::abs(end - start)},
           {"value_at_reference", value0},
           {"value_at_start", value0 * (1.0 + d.coeff_per_K * (start - d.reference_C))},
           {"value_at_end", value0 * (1.0 + d.coeff_per_K * (end - d.reference_C))}},
          {}};
}

}  // namespace

Truth build_truth(const Case& c, const RunFacts& f) {
  Truth t;
  t.config_path = c.machine.source;
  t.configured = c.machine.params;
  t.true_machine = f.true_machine;
  t.seed = c.seed;
  t.duration_s = c.duration_s;
  t.control_period_s = 1.0 / c.control.rate_Hz;
  t.switching_frequency_Hz = c.inverter.switching_frequency_Hz;
  t.u_dc_V = c.inverter.u_dc_V;
  t.modulation = modulation_name(c.inverter.modulation);
  t.initial_theta_rad = f.initial_theta_rad;
  t.noise = c.sensors;
  t.thermal = c.thermal;
  t.max_current_A = f.extremes.at_max_norm.norm();
  const Effects& e = c.effects;
  if (e.deadtime.on) t.effects.push_back(deadtime(c));
  if (e.delay.on) t.effects.push_back(delay(c));
  if (e.theta_offset.on) t.effects.push_back(theta_offset(c));
  if (e.current_offset.on) t.effects.push_back(current_offset(c));
  if (e.current_gain.on) t.effects.push_back(current_gain(c));
  for (EffectTruth& s : saturation(c, f)) t.effects.push_back(std::move(s));
  if (e.flux_harmonic_6.on) t.effects.push_back(harmonic("flux_harmonic_6", e.flux_harmonic_6.pair));
  if (e.flux_harmonic_12.on) t.effects.push_back(harmonic("flux_harmonic_12", e.flux_harmonic_12.pair));
  if (e.iron_loss.on) t.effects.push_back(iron_loss(c, f));
  if (e.rs_drift.on) {
    t.effects.push_back(drift("rs_drift", "r_s = r_s_Ohm*(1 + coeff_per_K*(T_winding - reference_C))", e.rs_drift,
                              c.thermal.winding, f.true_machine.r_s_Ohm, c.duration_s));
  }
  if (e.psim_drift.on) {
    t.effects.push_back(drift("psim_drift", "psi_m = psi_m_Wb*(1 + coeff_per_K*(T_magnet - reference_C))", e.psim_drift,
                              c.thermal.magnet, f.true_machine.psi_m_Wb, c.duration_s));
  }
  return t;
}

}  // namespace indep::detail
