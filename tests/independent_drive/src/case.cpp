#include "indep_drive/case.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "indep_drive/frames.hpp"
#include "indep_drive/random_streams.hpp"

#ifndef INDEP_DRIVE_DEFAULT_MAP
#define INDEP_DRIVE_DEFAULT_MAP ""
#endif

namespace indep {

const std::vector<EffectEntry>& effect_catalogue() {
  static const std::vector<EffectEntry> table = {
      {"deadtime", [](Effects& e) -> bool& { return e.deadtime.on; }, "smooth dead-time and device voltage per leg"},
      {"delay", [](Effects& e) -> bool& { return e.delay.on; }, "command applied late, whole and fractional periods"},
      {"theta_offset", [](Effects& e) -> bool& { return e.theta_offset.on; }, "encoder zero off the d axis"},
      {"current_offset", [](Effects& e) -> bool& { return e.current_offset.on; }, "current sensor offsets per phase"},
      {"current_gain", [](Effects& e) -> bool& { return e.current_gain.on; }, "current sensor gains per phase"},
      {"ld_saturation", [](Effects& e) -> bool& { return e.saturation.ld; }, "L_d against i_d (measured map)"},
      {"lq_saturation", [](Effects& e) -> bool& { return e.saturation.lq; }, "L_q against i_q (measured map)"},
      {"cross_saturation", [](Effects& e) -> bool& { return e.saturation.cross; },
       "psi_d against i_q, L_q against i_d (map)"},
      {"flux_harmonic_6", [](Effects& e) -> bool& { return e.flux_harmonic_6.on; },
       "6th rotor-frame flux harmonic (5th/7th EMF)"},
      {"flux_harmonic_12", [](Effects& e) -> bool& { return e.flux_harmonic_12.on; },
       "12th rotor-frame flux harmonic (11th/13th)"},
      {"iron_loss", [](Effects& e) -> bool& { return e.iron_loss.on; }, "resistance across the induced voltage"},
      {"rs_drift", [](Effects& e) -> bool& { return e.rs_drift.on; }, "R_s against winding temperature"},
      {"psim_drift", [](Effects& e) -> bool& { return e.psim_drift.on; }, "psi_m against magnet temperature"},
  };
  return table;
}

void enable_effects(Effects& e, std::string_view names) {
  std::size_t pos = 0;
  while (pos <= names.size()) {
    const std::size_t comma = std::min(names.find(',', pos), names.size());
    const std::string_view name = names.substr(pos, comma - pos);
    pos = comma + 1;
    if (name.empty() || name == "none") continue;
    const auto& table = effect_catalogue();
    const auto it = std::find_if(table.begin(), table.end(), [&](const EffectEntry& x) { return name == x.name; });
    if (it == table.end()) {
      std::string known;
      for (const EffectEntry& x : table) known += std::string(known.empty() ? "" : ", ") + x.name;
      throw std::invalid_argument("unknown effect '" + std::string(name) + "' (known: " + known + ")");
    }
    it->flag(e) = true;
  }
}

std::vector<std::string> enabled_effects(const Effects& e) {
  std::vector<std::string> names;
  Effects copy = e;
  for (const EffectEntry& x : effect_catalogue()) {
    if (x.flag(copy)) names.emplace_back(x.name);
  }
  return names;
}

namespace {

void fill(double& v, double value) {
  if (std::isnan(v)) v = value;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

int as_int(double v, int lo, int hi) {
  require(v == std::floor(v) && v >= lo && v <= hi,
          "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(v);
}

}  // namespace

Case resolve_defaults(Case c) {
  const double i_peak = c.machine.rated_peak_current_A();
  require(c.machine.params.pole_pairs > 0 && i_peak > 0.0, "case: no machine");
  require(c.duration_s > 0.0 && std::isfinite(c.duration_s), "duration_s must be > 0");
  require(c.control.rate_Hz >= 100.0 && c.control.rate_Hz <= 1e6, "control.rate_Hz must be in [100, 1e6]");
  require(c.control.substeps >= 1 && c.control.substeps <= 64, "control.substeps must be in [1, 64]");
  const double t_c = 1.0 / c.control.rate_Hz;
  fill(c.inverter.u_dc_V, std::sqrt(2.0) * c.machine.rated.voltage_ll_rms_V);
  fill(c.inverter.switching_frequency_Hz, c.control.rate_Hz);
  require(c.inverter.u_dc_V > 0.0 && c.inverter.switching_frequency_Hz > 0.0,
          "inverter: u_dc_V and switching_frequency_Hz must be > 0");

  Effects& e = c.effects;
  fill(e.deadtime.v_device_V, 0.002 * c.inverter.u_dc_V);
  fill(e.deadtime.i_band_A, 0.03 * i_peak);
  require(e.deadtime.t_dead_s >= 0.0 && e.deadtime.v_device_V >= 0.0 && e.deadtime.i_band_A > 0.0,
          "deadtime: t_dead_s, v_device_V >= 0 and i_band_A > 0");
  if (!std::isnan(e.delay.periods)) e.delay.delay_s = e.delay.periods * t_c;
  fill(e.delay.delay_s, t_c);
  e.delay.periods = e.delay.delay_s / t_c;
  require(e.delay.delay_s >= 0.0 && e.delay.periods < DelayLine::kMaxPeriods,
          "delay: delay_s must be in [0, 4 control periods)");
  for (double& v : e.current_offset.value) fill(v, 0.015 * i_peak);
  for (double g : e.current_gain.value) require(g > 0.0, "current_gain: every phase's gain must be > 0");
  if (e.saturation.map_path.empty()) e.saturation.map_path = INDEP_DRIVE_DEFAULT_MAP;
  fill(e.saturation.full_scale_current_A, i_peak);
  require(e.saturation.full_scale_current_A > 0.0 && e.saturation.depth >= 0.0,
          "saturation: full_scale_current_A > 0, depth >= 0");
  const double e_rated = c.machine.rated_omega_el_rad_s() * c.machine.params.psi_m_Wb;
  fill(e.iron_loss.r_fe_Ohm, 1.5 * e_rated * e_rated / (0.01 * c.machine.reference_power_W()));
  require(e.iron_loss.r_fe_Ohm > 0.0, "iron_loss.r_fe_Ohm must be > 0");

  ThermalSettings& th = c.thermal;
  if (e.rs_drift.on && th.winding.start_C == th.winding.end_C) th.winding = {25.0, 85.0, 0.0};
  if (e.psim_drift.on && th.magnet.start_C == th.magnet.end_C) th.magnet = {25.0, 65.0, 0.0};
  for (TemperatureTrack* t : {&th.winding, &th.magnet}) {
    if (t->tau_s <= 0.0) t->tau_s = c.duration_s / 3.0;
  }
  fill(e.rs_drift.reference_C, th.winding.start_C);
  fill(e.psim_drift.reference_C, th.magnet.start_C);

  SensorSettings& s = c.sensors;
  fill(s.current_noise_A, 0.0035 * i_peak);
  fill(s.adc_full_scale_A, 2.5 * i_peak);
  fill(s.u_dc_noise_V, 0.002 * c.inverter.u_dc_V);
  fill(s.u_dc_full_scale_V, 1.5 * c.inverter.u_dc_V);
  require(s.current_noise_A >= 0.0 && s.u_dc_noise_V >= 0.0 && s.adc_full_scale_A > 0.0 && s.u_dc_full_scale_V > 0.0 &&
              s.adc_bits >= 0 && s.adc_bits <= 24 && s.u_dc_adc_bits >= 0 && s.u_dc_adc_bits <= 24 &&
              s.encoder_counts_per_rev >= 0,
          "sensors: noise >= 0, full scales > 0, bits in [0, 24]");

  fill(c.control.bandwidth_Hz, c.control.rate_Hz / 40.0);
  fill(c.control.current_limit_A, 1.5 * i_peak);
  require(c.control.bandwidth_Hz >= 0.0 && c.control.current_limit_A > 0.0,
          "control: bandwidth_Hz >= 0, current_limit_A > 0");

  AveragedSettings& a = c.averaged;
  require(a.rate_Hz > 0.0 && a.jitter_rel >= 0.0 && a.jitter_rel < 1.0 && a.min_interval_s > 0.0 &&
              a.max_interval_s >= a.min_interval_s,
          "averaged: rate_Hz > 0, jitter_rel in [0, 1), 0 < min_interval_s <= max_interval_s");
  return c;
}

namespace {

using Entry = ParameterEntry;

const std::vector<Entry>& table() {
  static const std::vector<Entry> t = {
      {"duration_s", "s", [](Case& c, double v) { c.duration_s = v; }},
      {"draw.psi_m_span_rel", "1", [](Case& c, double v) { c.draw.psi_m_span_rel = v; }},
      {"draw.r_s_span_rel", "1", [](Case& c, double v) { c.draw.r_s_span_rel = v; }},
      {"draw.l_span_rel", "1", [](Case& c, double v) { c.draw.l_span_rel = v; }},
      {"draw.psi_m_rel", "1", [](Case& c, double v) { c.draw.psi_m_rel = v; }},
      {"draw.r_s_rel", "1", [](Case& c, double v) { c.draw.r_s_rel = v; }},
      {"draw.l_d_rel", "1", [](Case& c, double v) { c.draw.l_d_rel = v; }},
      {"draw.l_q_rel", "1", [](Case& c, double v) { c.draw.l_q_rel = v; }},
      {"deadtime.t_dead_s", "s", [](Case& c, double v) { c.effects.deadtime.t_dead_s = v; }},
      {"deadtime.v_device_V", "V", [](Case& c, double v) { c.effects.deadtime.v_device_V = v; }},
      {"deadtime.i_band_A", "A", [](Case& c, double v) { c.effects.deadtime.i_band_A = v; }},
      {"delay.delay_s", "s",
       [](Case& c, double v) {
         c.effects.delay.delay_s = v;
         c.effects.delay.periods = kAuto;
       }},
      {"delay.periods", "1", [](Case& c, double v) { c.effects.delay.periods = v; }},
      {"theta_offset.offset_rad", "rad", [](Case& c, double v) { c.effects.theta_offset.offset_rad = v; }},
      {"theta_offset.offset_deg", "deg", [](Case& c, double v) { c.effects.theta_offset.offset_rad = v * kPi / 180.0; }},
      {"current_offset.a_A", "A", [](Case& c, double v) { c.effects.current_offset.value[0] = v; }},
      {"current_offset.b_A", "A", [](Case& c, double v) { c.effects.current_offset.value[1] = v; }},
      {"current_offset.c_A", "A", [](Case& c, double v) { c.effects.current_offset.value[2] = v; }},
      {"current_gain.a", "1", [](Case& c, double v) { c.effects.current_gain.value[0] = v; }},
      {"current_gain.b", "1", [](Case& c, double v) { c.effects.current_gain.value[1] = v; }},
      {"current_gain.c", "1", [](Case& c, double v) { c.effects.current_gain.value[2] = v; }},
      {"saturation.full_scale_current_A", "A", [](Case& c, double v) { c.effects.saturation.full_scale_current_A = v; }},
      {"saturation.depth", "1", [](Case& c, double v) { c.effects.saturation.depth = v; }},
      {"saturation.degree", "3-7", [](Case& c, double v) { c.effects.saturation.degree = as_int(v, 3, 7); }},
      {"flux_harmonic_6.h5_rel", "1", [](Case& c, double v) { c.effects.flux_harmonic_6.pair.h_lo_rel = v; }},
      {"flux_harmonic_6.h5_phase_rad", "rad", [](Case& c, double v) { c.effects.flux_harmonic_6.pair.phi_lo_rad = v; }},
      {"flux_harmonic_6.h7_rel", "1", [](Case& c, double v) { c.effects.flux_harmonic_6.pair.h_hi_rel = v; }},
      {"flux_harmonic_6.h7_phase_rad", "rad", [](Case& c, double v) { c.effects.flux_harmonic_6.pair.phi_hi_rad = v; }},
      {"flux_harmonic_12.h11_rel", "1", [](Case& c, double v) { c.effects.flux_harmonic_12.pair.h_lo_rel = v; }},
      {"flux_harmonic_12.h11_phase_rad", "rad", [](Case& c, double v) { c.effects.flux_harmonic_12.pair.phi_lo_rad = v; }},
      {"flux_harmonic_12.h13_rel", "1", [](Case& c, double v) { c.effects.flux_harmonic_12.pair.h_hi_rel = v; }},
      {"flux_harmonic_12.h13_phase_rad", "rad", [](Case& c, double v) { c.effects.flux_harmonic_12.pair.phi_hi_rad = v; }},
      {"iron_loss.r_fe_Ohm", "Ohm", [](Case& c, double v) { c.effects.iron_loss.r_fe_Ohm = v; }},
      {"rs_drift.coeff_per_K", "1/K", [](Case& c, double v) { c.effects.rs_drift.coeff_per_K = v; }},
      {"rs_drift.reference_C", "degC", [](Case& c, double v) { c.effects.rs_drift.reference_C = v; }},
      {"psim_drift.coeff_per_K", "1/K", [](Case& c, double v) { c.effects.psim_drift.coeff_per_K = v; }},
      {"psim_drift.reference_C", "degC", [](Case& c, double v) { c.effects.psim_drift.reference_C = v; }},
      {"sensors.current_noise_A", "A", [](Case& c, double v) { c.sensors.current_noise_A = v; }},
      {"sensors.adc_bits", "0-24", [](Case& c, double v) { c.sensors.adc_bits = as_int(v, 0, 24); }},
      {"sensors.adc_full_scale_A", "A", [](Case& c, double v) { c.sensors.adc_full_scale_A = v; }},
      {"sensors.encoder_counts_per_rev", "1",
       [](Case& c, double v) { c.sensors.encoder_counts_per_rev = as_int(v, 0, 1 << 30); }},
      {"sensors.u_dc_noise_V", "V", [](Case& c, double v) { c.sensors.u_dc_noise_V = v; }},
      {"sensors.u_dc_adc_bits", "0-24", [](Case& c, double v) { c.sensors.u_dc_adc_bits = as_int(v, 0, 24); }},
      {"sensors.u_dc_full_scale_V", "V", [](Case& c, double v) { c.sensors.u_dc_full_scale_V = v; }},
      {"sensors.omega_noise_rad_s", "rad/s", [](Case& c, double v) { c.sensors.omega_noise_rad_s = v; }},
      {"sensors.temperature_noise_K", "K", [](Case& c, double v) { c.sensors.temperature_noise_K = v; }},
      {"inverter.u_dc_V", "V", [](Case& c, double v) { c.inverter.u_dc_V = v; }},
      {"inverter.switching_frequency_Hz", "Hz", [](Case& c, double v) { c.inverter.switching_frequency_Hz = v; }},
      {"control.rate_Hz", "Hz", [](Case& c, double v) { c.control.rate_Hz = v; }},
      {"control.substeps", "1-64", [](Case& c, double v) { c.control.substeps = as_int(v, 1, 64); }},
      {"control.bandwidth_Hz", "Hz", [](Case& c, double v) { c.control.bandwidth_Hz = v; }},
      {"control.current_limit_A", "A", [](Case& c, double v) { c.control.current_limit_A = v; }},
      {"control.angle_advance_periods", "1", [](Case& c, double v) { c.control.angle_advance_periods = v; }},
      {"profile.max_speed_pu", "1", [](Case& c, double v) { c.profile.max_speed_pu = v; }},
      {"profile.max_torque_pu", "1", [](Case& c, double v) { c.profile.max_torque_pu = v; }},
      {"thermal.winding.start_C", "degC", [](Case& c, double v) { c.thermal.winding.start_C = v; }},
      {"thermal.winding.end_C", "degC", [](Case& c, double v) { c.thermal.winding.end_C = v; }},
      {"thermal.winding.tau_s", "s", [](Case& c, double v) { c.thermal.winding.tau_s = v; }},
      {"thermal.magnet.start_C", "degC", [](Case& c, double v) { c.thermal.magnet.start_C = v; }},
      {"thermal.magnet.end_C", "degC", [](Case& c, double v) { c.thermal.magnet.end_C = v; }},
      {"thermal.magnet.tau_s", "s", [](Case& c, double v) { c.thermal.magnet.tau_s = v; }},
      {"averaged.rate_Hz", "Hz", [](Case& c, double v) { c.averaged.rate_Hz = v; }},
      {"averaged.jitter_rel", "1", [](Case& c, double v) { c.averaged.jitter_rel = v; }},
      {"averaged.min_interval_s", "s", [](Case& c, double v) { c.averaged.min_interval_s = v; }},
      {"averaged.max_interval_s", "s", [](Case& c, double v) { c.averaged.max_interval_s = v; }},
  };
  return t;
}

}  // namespace

const std::vector<ParameterEntry>& parameter_catalogue() { return table(); }

void set_parameter(Case& c, std::string_view key, double value) {
  const auto& t = table();
  const auto it = std::find_if(t.begin(), t.end(), [&](const Entry& e) { return key == e.key; });
  if (it == t.end())
    throw std::invalid_argument("unknown parameter '" + std::string(key) + "' (--list-parameters shows them)");
  if (!std::isfinite(value)) throw std::invalid_argument(std::string(key) + ": not a finite number");
  try {
    it->set(c, value);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(key) + ": " + e.what());
  }
}

void draw_effect_parameters(Case& c) {
  c = resolve_defaults(std::move(c));
  std::mt19937_64 rng = stream_rng(c.seed, Stream::effects);
  auto uniform = [&rng](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  auto sign = [&] { return uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0; };
  auto phase = [&] { return static_cast<int>(std::min(2.0, std::floor(uniform(0.0, 3.0)))); };
  const double i_peak = c.machine.rated_peak_current_A();
  const double t_c = 1.0 / c.control.rate_Hz;
  Effects& e = c.effects;
  // Every draw is made whether or not its effect is on, so one effect's parameters do not depend on the others'.
  const double t_dead = uniform(0.5e-6, 3e-6);
  const double whole = std::floor(uniform(1.0, 4.0));
  const double frac = uniform(0.0, 1.0) < 0.5 ? 0.0 : uniform(0.0, 1.0);
  const double theta = sign() * uniform(1.0, 6.0) * kPi / 180.0;
  const int off_phase = phase();
  const double offset = sign() * uniform(0.005, 0.03) * i_peak;
  const int gain_phase = phase();
  const double gain = 1.0 + sign() * uniform(0.01, 0.05);
  const double depth = uniform(1.0, 3.0), full_scale = uniform(0.8, 1.2) * i_peak;
  const HarmonicPair h6{6, uniform(0.005, 0.03), uniform(-kPi, kPi), uniform(0.003, 0.02), uniform(-kPi, kPi)};
  const HarmonicPair h12{12, uniform(0.002, 0.01), uniform(-kPi, kPi), uniform(0.002, 0.008), uniform(-kPi, kPi)};
  const double loss_share = uniform(0.005, 0.03);
  const double alpha_cu = uniform(0.0037, 0.0041), alpha_pm = uniform(-0.0012, -0.0008);
  const TemperatureTrack winding{uniform(20.0, 40.0), 0.0, 0.0}, magnet{uniform(20.0, 40.0), 0.0, 0.0};
  const double winding_rise = uniform(30.0, 70.0), magnet_rise = uniform(20.0, 50.0);

  if (e.deadtime.on) e.deadtime.t_dead_s = t_dead;
  if (e.delay.on) {
    e.delay.periods = whole + frac;
    e.delay.delay_s = e.delay.periods * t_c;
  }
  if (e.theta_offset.on) e.theta_offset.offset_rad = theta;
  if (e.current_offset.on) {
    e.current_offset.value = {0.0, 0.0, 0.0};
    e.current_offset.value[static_cast<std::size_t>(off_phase)] = offset;
  }
  if (e.current_gain.on) {
    e.current_gain.value = {1.0, 1.0, 1.0};
    e.current_gain.value[static_cast<std::size_t>(gain_phase)] = gain;
  }
  if (e.saturation.any()) {
    e.saturation.depth = depth;
    e.saturation.full_scale_current_A = full_scale;
  }
  if (e.flux_harmonic_6.on) e.flux_harmonic_6.pair = h6;
  if (e.flux_harmonic_12.on) e.flux_harmonic_12.pair = h12;
  if (e.iron_loss.on) {
    const double e_rated = c.machine.rated_omega_el_rad_s() * c.machine.params.psi_m_Wb;
    e.iron_loss.r_fe_Ohm = 1.5 * e_rated * e_rated / (loss_share * c.machine.reference_power_W());
  }
  if (e.rs_drift.on) {
    e.rs_drift.coeff_per_K = alpha_cu;
    c.thermal.winding = {winding.start_C, winding.start_C + winding_rise, c.duration_s / 3.0};
    e.rs_drift.reference_C = winding.start_C;
  }
  if (e.psim_drift.on) {
    e.psim_drift.coeff_per_K = alpha_pm;
    c.thermal.magnet = {magnet.start_C, magnet.start_C + magnet_rise, c.duration_s / 3.0};
    e.psim_drift.reference_C = magnet.start_C;
  }
}

}  // namespace indep
