#include "rpem/io/machine_config.hpp"

#include <array>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "rpem/core/non_finite.hpp"
#include "rpem/core/per_unit.hpp"
#include "rpem/core/plausibility.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {
namespace {

using core::kInf;

core::MachineSi parse_machine(YamlMap m) {
  core::MachineSi out;
  YamlMap rated = m.map("rated");
  out.rated.voltage_ll_rms_V = rated.number("voltage_ll_rms_V", 1.0, 1e5);
  out.rated.current_rms_A = rated.number("current_rms_A", 1e-3, 1e5);
  out.rated.speed_rpm = rated.number("speed_rpm", 1.0, 1e6);
  out.rated.pole_pairs = static_cast<int>(rated.integer("pole_pairs", 1, 100));
  (void)rated.number_or("power_W", 0.0, 0.0, 1e9);    // informational
  (void)rated.number_or("torque_Nm", 0.0, 0.0, 1e7);  // informational
  rated.finish();
  out.r_s_Ohm = m.number("r_s_Ohm", 1e-6, 1e4);
  out.l_d_H = m.number("l_d_H", 1e-8, 100.0);
  out.l_q_H = m.number("l_q_H", 1e-8, 100.0);
  out.psi_m_Wb = m.number("psi_m_Wb", 1e-6, 100.0);
  m.finish();
  return out;
}

core::GainSequences parse_sequences(YamlMap g, bool with_hessian) {
  core::GainSequences s;
  const char* names[2] = {"psi_m", "r_s"};
  for (int j = 0; j < 2; ++j) {
    YamlMap p = g.map(names[j]);
    s.hessian[j] = with_hessian ? p.number("hessian", 0.0, 1.0) : 0.0;
    s.gain[j] = p.number("gain", 0.0, 1.0);
    p.finish();
  }
  g.finish();
  return s;
}

core::GradientForm parse_form(YamlMap& m, const char* key, core::GradientForm fallback) {
  const char* fallback_name = fallback == core::GradientForm::kDynamic ? "dynamic" : "steady_state";
  return m.choice_or(key, fallback_name, {"steady_state", "dynamic"}) == "dynamic" ? core::GradientForm::kDynamic
                                                                                   : core::GradientForm::kSteadyState;
}

void parse_initial_hessians(YamlMap hess, core::EstimatorSettings& s) {
  const auto r0 = hess.numbers("sga_pu", 2, 0.0, 1e6);
  s.initial_sga_hessian_pu = {r0[0], r0[1]};
  const auto big_r0 = hess.numbers("gna_pu", 3, -1e6, 1e6);  // [R11, R12, R22]
  s.initial_gna_hessian_pu << big_r0[0], big_r0[1], big_r0[1], big_r0[2];
  if (big_r0[0] < 0.0 || big_r0[2] < 0.0 || big_r0[0] * big_r0[2] < big_r0[1] * big_r0[1]) {
    hess.fail("gna_pu", "R[0] = [[R11, R12], [R12, R22]] must be positive semi-definite");
  }
  hess.finish();
}

void parse_floors(YamlMap floors, core::EstimatorSettings& s) {
  s.floors.sga_hessian_min_pu = floors.number("sga_hessian_min_pu", 0.0, kInf);
  s.floors.gna_determinant_min_pu = floors.number("gna_determinant_min_pu", 0.0, kInf);
  s.floors.gna_eigenvalue_min_pu = floors.number("gna_eigenvalue_min_pu", 0.0, kInf);
  s.floors.phyint_denominator_min_pu = floors.number("phyint_denominator_min_pu", 0.0, kInf);
  floors.finish();
}

/// The averaged-sample estimator (docs/derivations.md §11); its gains are those of estimator.gains, as rates
/// per second.
void parse_averaged(YamlMap& a, core::EstimatorSettings& s) {
  s.averaged.max_interval_s = a.number_or("max_interval_s", s.averaged.max_interval_s, 1e-4, 10.0);
  s.averaged.inductive_correction = a.boolean_or("inductive_correction", s.averaged.inductive_correction);
  s.averaged.instrument_time_constant_s =
      a.number_or("instrument_time_constant_s", s.averaged.instrument_time_constant_s, 0.0, 10.0);
  s.averaged.control_period_s = a.number_or("control_period_s", s.averaged.control_period_s, 0.0, 1e-2);
  s.averaged.current_sample_at = a.number_or("current_sample_at", s.averaged.current_sample_at, 0.0, 1.0);
  s.averaged.voltage_is_command = a.choice_or("voltage_reported", "mean", {"mean", "command"}) == "command";
  if (s.averaged.voltage_is_command && !(s.averaged.control_period_s > 0.0)) {
    a.fail("voltage_reported", "command needs control_period_s (the period the command is held)");
  }
  a.finish();
}

/// The regime classification (core/regime.hpp, docs/derivations.md §13).
void parse_regimes(YamlMap& g, core::RegimeSettings& r) {
  r.enabled = g.boolean_or("enabled", r.enabled);
  r.significance_sigma = g.number_or("significance_sigma", r.significance_sigma, 1.0, 10.0);
  r.voltage_resolution_V = g.number_or("voltage_resolution_V", r.voltage_resolution_V, 0.0, 1e3);
  r.current_resolution_A = g.number_or("current_resolution_A", r.current_resolution_A, 0.0, 1e3);
  r.speed_resolution_rad_s = g.number_or("speed_resolution_rad_s", r.speed_resolution_rad_s, 0.0, 1e4);
  r.inductance_tolerance = g.number_or("inductance_tolerance", r.inductance_tolerance, 0.0, 10.0);
  r.angle_tolerance_rad = g.number_or("angle_tolerance_rad", r.angle_tolerance_rad, 0.0, 1.5);
  r.angle_source_assumed = !g.has("angle_source");
  const std::string source =
      g.choice_or("angle_source", r.sensorless ? "sensorless" : "sensor", {"sensor", "sensorless", "hall"});
  r.sensorless = source != "sensor";
  for (const char* key : {"hall_frame_error_rad", "hall_below_speed_rad_s", "hall_interpolation_speed_rad_s"}) {
    if (source != "hall" && g.has(key)) g.fail(key, "applies to angle_source: hall only");
  }
  if (source == "hall") {
    r.hall_frame_error_rad = g.number_or("hall_frame_error_rad", core::kHallFrameErrorRad, 1e-3, core::kPi / 2.0);
    r.hall_below_speed_rad_s = g.number_or("hall_below_speed_rad_s", core::kHallBelowSpeedRadS, 0.0, 1e5);
    r.hall_interpolation_speed_rad_s =
        g.number_or("hall_interpolation_speed_rad_s", core::kHallInterpolationSpeedRadS, 0.0, 1e5);
  }
  g.finish();
}

core::EstimatorSettings parse_estimator(YamlMap e, const core::MachineSi& machine) {
  core::EstimatorSettings s;  // the defaults of every optional key (core/estimator.hpp, EstimatorOptions)
  s.algorithm = parse_algorithm(e.choice_or("algorithm", to_string(s.algorithm), {"sga", "gna", "phyint"}));
  const bool euler_default = s.discretization == core::Discretization::kExplicitEuler;
  s.discretization = e.choice_or("discretization", euler_default ? "explicit_euler" : "trapezoidal",
                                 {"trapezoidal", "explicit_euler"}) == "explicit_euler"
                         ? core::Discretization::kExplicitEuler
                         : core::Discretization::kTrapezoidal;
  if (auto g = e.optional_map("gradient")) {
    s.gradient_psi_m = parse_form(*g, "psi_m", s.gradient_psi_m);
    s.gradient_r_s = parse_form(*g, "r_s", s.gradient_r_s);
    g->finish();
  }
  s.nominal_sample_period_s = e.number_or("sample_period_s", s.nominal_sample_period_s, 1e-6, 1.0);
  s.max_sample_interval_s =
      e.number_or("max_sample_interval_s", core::EstimatorOptions::kMaxSampleIntervalPeriods * s.nominal_sample_period_s,
                  s.nominal_sample_period_s, 10.0);
  s.max_gap_carry_s = e.number_or("max_gap_carry_s", s.max_gap_carry_s, 0.0, 1.0);
  s.outlier_bound_sigma = e.number_or("outlier_bound_sigma", s.outlier_bound_sigma, 0.0, 100.0);
  if (auto a = e.optional_map("adapt")) {
    s.adapt_psi_m = a->boolean_or("psi_m", s.adapt_psi_m);
    s.adapt_r_s = a->boolean_or("r_s", s.adapt_r_s);
    a->finish();
  }

  YamlMap bounds = e.map("bounds");
  std::tie(s.psi_m_min_Wb, s.psi_m_max_Wb) = bounds.interval("psi_m_Wb", 1e-6, 100.0);
  std::tie(s.r_s_min_Ohm, s.r_s_max_Ohm) = bounds.interval("r_s_Ohm", 1e-6, 1e4);
  bounds.finish();

  s.initial_psi_m_Wb = machine.psi_m_Wb;
  s.initial_r_s_Ohm = machine.r_s_Ohm;
  if (auto init = e.optional_map("initial")) {
    s.initial_psi_m_Wb = init->number_or("psi_m_Wb", machine.psi_m_Wb, s.psi_m_min_Wb, s.psi_m_max_Wb);
    s.initial_r_s_Ohm = init->number_or("r_s_Ohm", machine.r_s_Ohm, s.r_s_min_Ohm, s.r_s_max_Ohm);
    init->finish();
  }
  // A start that estimator.initial does not set is the machine's offline value, which D_M must then hold
  // too: the estimator would otherwise move it onto the bound without a word.
  for (const auto& [start, lo, hi, key] : {std::tuple{s.initial_psi_m_Wb, s.psi_m_min_Wb, s.psi_m_max_Wb, "psi_m_Wb"},
                                           std::tuple{s.initial_r_s_Ohm, s.r_s_min_Ohm, s.r_s_max_Ohm, "r_s_Ohm"}}) {
    if (start < lo || start > hi) {
      std::ostringstream why;
      why << "excludes the estimator's start, machine." << key << " = " << start << " (set estimator.initial." << key
          << " or widen the bounds)";
      bounds.fail(key, why.str());
    }
  }

  YamlMap sched = e.map("scheduler");
  s.psi_m_min_speed_rpm = sched.number("psi_m_min_speed_rpm", 0.0, 1e6);
  s.r_s_max_speed_rpm = sched.number("r_s_max_speed_rpm", 0.0, 1e6);
  if (s.r_s_max_speed_rpm > s.psi_m_min_speed_rpm) {
    sched.fail("r_s_max_speed_rpm", "must not exceed psi_m_min_speed_rpm (|n_lim,1| >= |n_lim,2|, eq:GainSchedule)");
  }
  sched.finish();

  YamlMap gains = e.map("gains");
  s.gains[static_cast<int>(core::Algorithm::kSga)] = parse_sequences(gains.map("sga"), true);
  s.gains[static_cast<int>(core::Algorithm::kGna)] = parse_sequences(gains.map("gna"), true);
  s.gains[static_cast<int>(core::Algorithm::kPhyInt)] = parse_sequences(gains.map("phyint"), false);
  gains.finish();

  parse_initial_hessians(e.map("initial_hessian"), s);
  parse_floors(e.map("floors"), s);
  if (auto a = e.optional_map("averaged")) parse_averaged(*a, s);
  s.regimes.angle_source_assumed = true;  // unless the file says it (parse_regimes)
  if (auto g = e.optional_map("regimes")) parse_regimes(*g, s.regimes);
  e.finish();
  return s;
}

/// model_extensions' key of flux harmonic j: flux_harmonic_6, flux_harmonic_12.
std::string harmonic_key(std::size_t j) { return "flux_harmonic_" + std::to_string(core::kFluxHarmonicOrders[j]); }

/// A flux harmonic's keys and fields.
std::array<std::pair<const char*, double*>, 4> harmonic_fields(core::FluxHarmonic& f) {
  return {{{"d_cos_Wb", &f.d_cos_Wb}, {"d_sin_Wb", &f.d_sin_Wb}, {"q_cos_Wb", &f.q_cos_Wb}, {"q_sin_Wb", &f.q_sin_Wb}}};
}

core::InductanceCurve parse_inductance_curve(YamlMap m) {
  core::InductanceCurve c;  // a key left out keeps the nominal curve's value
  c.level = m.number_or("level", c.level, 0.05, 20.0);
  c.curvature_per_A2 = m.number_or("curvature_per_A2", c.curvature_per_A2, -1e3, 1e3);
  c.slope_per_A = m.number_or("slope_per_A", c.slope_per_A, -1e3, 1e3);
  m.finish();
  return c;
}

ParameterDrift parse_drift(YamlMap m, const char* ref_key, double ref_min, double ref_max) {
  ParameterDrift d;
  if (!m.has("coeff_per_K") && !m.has("rel_change")) m.fail("coeff_per_K", "a drift needs coeff_per_K or rel_change");
  if (m.has("coeff_per_K")) {
    core::DriftLaw law;
    law.coeff_per_K = m.number("coeff_per_K", -0.1, 0.1);
    law.reference_C = m.number_or("reference_C", law.reference_C, -273.0, 500.0);
    law.value_ref = m.number_or(ref_key, law.value_ref, ref_min, ref_max);
    d.law = law;
  } else {
    for (const char* key : {"reference_C", ref_key}) {
      if (m.has(key)) m.fail(key, "belongs to a drift against temperature (coeff_per_K)");
    }
  }
  if (m.has("rel_change")) d.rel_change = m.number("rel_change", -0.9, 10.0);
  m.finish();
  return d;
}

void parse_deadtime(YamlMap& d, const core::ModelExtensions& nominal, core::ModelExtensions& c) {
  c.deadtime_t_dead_s = d.number_or("t_dead_s", nominal.deadtime_t_dead_s, 0.0, 1e-3);
  c.switching_frequency_Hz = d.number_or("switching_frequency_Hz", nominal.switching_frequency_Hz, 0.0, 1e6);
  c.deadtime_v_err_V = d.number_or("v_err_V", nominal.deadtime_v_err_V, -1e4, 1e4);
  c.deadtime_current_band_A = d.number_or("current_band_A", nominal.deadtime_current_band_A, 0.0, 1e4);
  if (c.deadtime_t_dead_s > 0.0 && c.switching_frequency_Hz <= 0.0) {
    d.fail("switching_frequency_Hz", "t_dead_s needs the switching frequency");
  }
  d.finish();
}

/// current_offset and current_gain: lists of one phase's error each.
void parse_phase_errors(YamlMap& x, core::ModelExtensions& c) {
  for (const char* kind : {"current_offset", "current_gain"}) {
    if (!x.has(kind)) continue;
    for (YamlMap& p : x.maps(kind)) {
      const std::string phase = p.choice("phase", {"a", "b", "c"});
      const int k = phase[0] - 'a';
      if (std::string(kind) == "current_offset") {
        c.current_offset_A[k] = p.number("offset_A", -1e4, 1e4);
      } else {
        c.current_gain_error[k] = p.number("gain_error", -0.5, 0.5);
      }
      p.finish();
    }
  }
}

void parse_delay(YamlMap& d, double period_s, core::ModelExtensions& c) {
  c.delay_s = d.number("delay_s", 0.0, 1e-2);
  if (c.delay_s >= (core::kMaxDelayPeriods + 1) * period_s) {
    d.fail("delay_s",
           "must be below " + std::to_string(core::kMaxDelayPeriods + 1) + " sample periods (estimator.sample_period_s)");
  }
  d.finish();
}

void parse_extensions(YamlMap x, MachineConfig& config) {
  core::ModelExtensions& c = config.estimator.extensions;
  const core::ModelExtensions nominal;  // a key left out: its value in the nominal model
  if (auto d = x.optional_map("deadtime")) parse_deadtime(*d, nominal, c);
  if (auto t = x.optional_map("theta_offset")) {
    c.theta_offset_rad = t->number("offset_rad", -3.2, 3.2);
    t->finish();
  }
  parse_phase_errors(x, c);
  if (auto d = x.optional_map("delay")) parse_delay(*d, config.estimator.nominal_sample_period_s, c);
  if (auto k = x.optional_map("cross_saturation")) {
    c.cross_coupling_H_per_A = k->number_or("coupling_H_per_A", nominal.cross_coupling_H_per_A, -10.0, 10.0);
    c.cross_coupling_H_per_A2 = k->number_or("coupling_H_per_A2", nominal.cross_coupling_H_per_A2, -10.0, 10.0);
    k->finish();
  }
  for (std::size_t j = 0; j < core::kFluxHarmonicOrders.size(); ++j) {
    if (auto h = x.optional_map(harmonic_key(j))) {
      core::FluxHarmonic& f = c.flux_harmonics[j];
      f = nominal.flux_harmonics[j];
      for (auto [key, value] : harmonic_fields(f)) *value = h->number_or(key, *value, -100.0, 100.0);
      h->finish();
    }
  }
  if (auto l = x.optional_map("ld_saturation")) c.inductance_d = parse_inductance_curve(*l);
  if (auto l = x.optional_map("lq_saturation")) c.inductance_q = parse_inductance_curve(*l);
  if (auto f = x.optional_map("iron_loss")) {
    c.iron_loss_r_fe_Ohm = f->number("r_fe_Ohm", 1e-3, 1e9);
    f->finish();
  }
  if (auto r = x.optional_map("rs_drift")) config.rs_drift = parse_drift(*r, "r_s_ref_Ohm", 1e-6, 1e4);
  if (auto p = x.optional_map("psim_drift")) config.psim_drift = parse_drift(*p, "psi_m_ref_Wb", 1e-6, 100.0);
  x.finish();
}

}  // namespace

namespace {

/// "{key: value, …}" from the pairs whose value is present.
class FlowMap {
 public:
  FlowMap& add(const char* key, double v) {
    text_ += (text_.empty() ? "" : ", ") + std::string(key) + ": ";
    append_number(text_, v);
    return *this;
  }
  FlowMap& add(const char* key, const std::string& v) {
    text_ += (text_.empty() ? "" : ", ") + std::string(key) + ": " + v;
    return *this;
  }
  [[nodiscard]] std::string str() const { return "{" + text_ + "}"; }

 private:
  std::string text_;
};

void drift_entry(std::ostringstream& out, const char* key, const ParameterDrift& d, const char* ref_key) {
  if (!d.law && !d.rel_change) return;
  FlowMap m;
  if (d.law) {
    m.add("coeff_per_K", d.law->coeff_per_K).add("reference_C", d.law->reference_C);
    if (d.law->value_ref > 0.0) m.add(ref_key, d.law->value_ref);
  }
  if (d.rel_change) m.add("rel_change", *d.rel_change);
  out << "  " << key << ": " << m.str() << "\n";
}

void curve_entry(std::ostringstream& out, const char* key, const core::InductanceCurve& c) {
  if (c.nominal()) return;
  FlowMap m;
  m.add("level", c.level).add("curvature_per_A2", c.curvature_per_A2);
  if (c.slope_per_A != 0.0) m.add("slope_per_A", c.slope_per_A);
  out << "  " << key << ": " << m.str() << "\n";
}

}  // namespace

void check_log_supports(const MachineConfig& c, const std::string& config_name, bool log_has_u_dc,
                        const std::string& log_path) {
  if (c.estimator.extensions.deadtime_t_dead_s > 0.0 && !log_has_u_dc) {
    throw ConfigError(config_name, 0, 0, "model_extensions.deadtime.t_dead_s",
                      "a dead time in seconds needs the DC-link voltage, and " + log_path +
                          " has no u_dc column (give the error as v_err_V instead)");
  }
}

DriveLogLimits machine_limits(const core::MachineSi& machine) {
  const core::PerUnitBase base = core::PerUnitBase::from_rated(machine.rated);
  const core::PlausibleMagnitudes narrowed = core::machine_plausible(machine.rated);
  DriveLogLimits limits;
  auto narrow = [](Bound& bound, double max_abs, double base_value, const char* what, const char* unit) {
    if (!(max_abs < bound.max_abs)) return;
    char why[160];
    std::snprintf(why, sizeof why, "%g x the configured machine's %s %.4g %s, machine.rated", core::kRatedMultipleLimit,
                  what, base_value, unit);
    bound = {max_abs, why};
  };
  narrow(limits.current_A, narrowed.current_A, base.current_A, "rated peak phase current", "A");
  narrow(limits.voltage_V, narrowed.voltage_V, base.voltage_V, "rated peak phase voltage", "V");
  narrow(limits.speed_rad_s, narrowed.speed_rad_s, base.omega_el_rad_s, "rated electrical speed", "rad/s");
  return limits;
}

DriveLogLimits log_limits(const MachineConfig& config) {
  DriveLogLimits limits = machine_limits(config.machine);
  limits.control_period_s = config.estimator.averaged.control_period_s;
  return limits;
}

std::string model_extensions_yaml(const MachineConfig& c) {
  const core::ModelExtensions& x = c.estimator.extensions;
  std::ostringstream out;
  if (x.deadtime_v_err_V != 0.0 || x.deadtime_t_dead_s != 0.0) {
    FlowMap m;
    if (x.deadtime_t_dead_s != 0.0) m.add("t_dead_s", x.deadtime_t_dead_s);
    if (x.switching_frequency_Hz != 0.0) m.add("switching_frequency_Hz", x.switching_frequency_Hz);
    if (x.deadtime_v_err_V != 0.0) m.add("v_err_V", x.deadtime_v_err_V);
    if (x.deadtime_current_band_A != 0.0) m.add("current_band_A", x.deadtime_current_band_A);
    out << "  deadtime: " << m.str() << "\n";
  }
  if (x.theta_offset_rad != 0.0) out << "  theta_offset: " << FlowMap().add("offset_rad", x.theta_offset_rad).str() << "\n";
  const char* const phases[3] = {"a", "b", "c"};
  for (const auto& [key, values, field] : {std::tuple{"current_offset", x.current_offset_A, "offset_A"},
                                           std::tuple{"current_gain", x.current_gain_error, "gain_error"}}) {
    std::string items;
    for (int k = 0; k < 3; ++k) {
      if (values[k] == 0.0) continue;
      items += (items.empty() ? "" : ", ") + FlowMap().add("phase", std::string(phases[k])).add(field, values[k]).str();
    }
    if (!items.empty()) out << "  " << key << ": [" << items << "]\n";
  }
  if (x.delay_s != 0.0) out << "  delay: " << FlowMap().add("delay_s", x.delay_s).str() << "\n";
  curve_entry(out, "ld_saturation", x.inductance_d);
  curve_entry(out, "lq_saturation", x.inductance_q);
  if (x.iron_loss_r_fe_Ohm > 0.0) out << "  iron_loss: " << FlowMap().add("r_fe_Ohm", x.iron_loss_r_fe_Ohm).str() << "\n";
  if (x.cross_coupling_H_per_A != 0.0 || x.cross_coupling_H_per_A2 != 0.0) {
    FlowMap m;
    if (x.cross_coupling_H_per_A != 0.0) m.add("coupling_H_per_A", x.cross_coupling_H_per_A);
    if (x.cross_coupling_H_per_A2 != 0.0) m.add("coupling_H_per_A2", x.cross_coupling_H_per_A2);
    out << "  cross_saturation: " << m.str() << "\n";
  }
  for (std::size_t j = 0; j < core::kFluxHarmonicOrders.size(); ++j) {
    core::FluxHarmonic h = x.flux_harmonics[j];
    if (h.nominal()) continue;
    FlowMap m;
    for (auto [key, value] : harmonic_fields(h)) {
      if (*value != 0.0) m.add(key, *value);
    }
    out << "  " << harmonic_key(j) << ": " << m.str() << "\n";
  }
  drift_entry(out, "rs_drift", c.rs_drift, "r_s_ref_Ohm");
  drift_entry(out, "psim_drift", c.psim_drift, "psi_m_ref_Wb");
  const std::string body = out.str();
  return body.empty() ? "" : "model_extensions:\n" + body;
}

namespace {

/// `line`, a direct child `key: value` of a block at `indent`, with its value replaced by `value`, followed by
/// `comment` and the value it replaced. False where the line is not that key's.
bool replace_child_value(std::string& line, std::size_t indent, const std::string& key_name, double value,
                         const std::string& comment) {
  const std::string key = key_name + ":";
  if (line.compare(indent, key.size(), key) != 0) return false;
  std::string old = line.substr(indent + key.size());
  old = old.substr(0, old.find('#'));
  old.erase(0, old.find_first_not_of(' '));
  old.erase(old.find_last_not_of(' ') + 1);
  line = line.substr(0, indent).append(key).append(" ");
  append_number(line, value);
  line.append("  # ").append(comment).append(" (was ").append(old).append(")");
  return true;
}

/// In a flow map's text ("{psi_m_Wb: 0.0045, r_s_Ohm: 0.022}"), the value of `key` replaced; the old value's text,
/// or nothing where the map has no such key.
std::optional<std::string> replace_flow_value(std::string& flow, const std::string& key, double value) {
  for (std::size_t at = flow.find(key + ":"); at != std::string::npos; at = flow.find(key + ":", at + 1)) {
    if (at > 0 && flow[at - 1] != '{' && flow[at - 1] != ',' && flow[at - 1] != ' ') continue;  // a longer key's end
    const std::size_t begin = flow.find_first_not_of(' ', at + key.size() + 1);
    if (begin == std::string::npos) return std::nullopt;
    std::size_t end = flow.find_first_of(",}", begin);
    if (end == std::string::npos) end = flow.size();
    std::string old = flow.substr(begin, end - begin);
    old.erase(old.find_last_not_of(' ') + 1);
    std::string number;
    append_number(number, value);
    flow.replace(begin, old.size(), number);
    return old;
  }
  return std::nullopt;
}

}  // namespace

std::string replace_machine_values(const std::string& yaml_text, const std::vector<std::pair<std::string, double>>& values,
                                   const std::string& comment) {
  std::istringstream in(yaml_text);
  std::string line, out;
  bool inside = false;
  std::vector<bool> done(values.size(), false);
  while (std::getline(in, line)) {
    const bool top_level = !line.empty() && line[0] != ' ' && line[0] != '\t' && line[0] != '#';
    if (top_level) inside = line.rfind("machine:", 0) == 0;
    const std::size_t indent = line.find_first_not_of(' ');
    if (inside && indent != std::string::npos && indent > 0) {
      // A direct child: the first indented level of the section.
      for (std::size_t j = 0; j < values.size(); ++j) {
        if (replace_child_value(line, indent, values[j].first, values[j].second, comment)) done[j] = true;
      }
    }
    out += line + "\n";
  }
  for (std::size_t j = 0; j < values.size(); ++j) {
    if (!done[j]) throw ConfigError("<configuration text>", 0, 0, "machine." + values[j].first, "not found to replace");
  }
  return out;
}

std::string replace_estimator_initial(const std::string& yaml_text,
                                      const std::vector<std::pair<std::string, double>>& values,
                                      const std::string& comment) {
  std::istringstream in(yaml_text);
  std::string line, out;
  bool inside = false, in_block = false;
  std::size_t child_indent = std::string::npos, block_indent = 0;
  while (std::getline(in, line)) {
    const bool top_level = !line.empty() && line[0] != ' ' && line[0] != '\t' && line[0] != '#';
    if (top_level) {
      inside = line.rfind("estimator:", 0) == 0;
      in_block = false;
      child_indent = std::string::npos;
    }
    const std::size_t indent = line.find_first_not_of(' ');
    if (inside && indent != std::string::npos && indent > 0 && line[indent] != '#') {
      if (in_block && indent <= block_indent) in_block = false;
      if (child_indent == std::string::npos) child_indent = indent;
      if (in_block) {
        for (const auto& [key, value] : values) replace_child_value(line, indent, key, value, comment);
      } else if (indent == child_indent && line.compare(indent, 8, "initial:") == 0) {
        std::string rest = line.substr(indent + 8);
        rest = rest.substr(0, rest.find('#'));
        if (rest.find('{') == std::string::npos) {
          in_block = true;  // `initial:` and its keys below it
          block_indent = indent;
        } else {
          std::string keys, olds;
          for (const auto& [key, value] : values) {
            if (const std::optional<std::string> old = replace_flow_value(rest, key, value)) {
              keys += (keys.empty() ? "" : ", ") + key;
              olds += (olds.empty() ? "" : ", ") + *old;
            }
          }
          rest.erase(rest.find_last_not_of(' ') + 1);
          line.erase(indent + 8).append(rest);
          if (!keys.empty())
            line.append("  # ").append(keys).append(": ").append(comment).append(" (was ").append(olds).append(")");
        }
      }
    }
    out += line + "\n";
  }
  return out;
}

std::string replace_model_extensions(const std::string& yaml_text, const std::string& section) {
  std::istringstream in(yaml_text);
  std::string line, out;
  bool inside = false;
  while (std::getline(in, line)) {
    const bool top_level = !line.empty() && line[0] != ' ' && line[0] != '\t' && line[0] != '#';
    if (top_level) inside = line.rfind("model_extensions:", 0) == 0;
    if (!inside) out += line + "\n";
  }
  while (out.size() >= 2 && out[out.size() - 1] == '\n' && out[out.size() - 2] == '\n') out.pop_back();
  return section.empty() ? out : out + "\n" + section;
}

const char* to_string(core::Algorithm a) noexcept {
  switch (a) {
    case core::Algorithm::kSga:
      return "sga";
    case core::Algorithm::kGna:
      return "gna";
    case core::Algorithm::kPhyInt:
      return "phyint";
  }
  return "?";
}

core::Algorithm parse_algorithm(const std::string& name) {
  if (name == "sga") return core::Algorithm::kSga;
  if (name == "gna") return core::Algorithm::kGna;
  if (name == "phyint") return core::Algorithm::kPhyInt;
  throw std::invalid_argument("unknown algorithm '" + name + "' (expected sga, gna or phyint)");
}

MachineConfig parse_machine_config(YamlMap& root) {
  MachineConfig c;
  c.machine = parse_machine(root.map("machine"));
  c.estimator = parse_estimator(root.map("estimator"), c.machine);
  if (auto x = root.optional_map("model_extensions")) parse_extensions(*x, c);
  return c;
}

std::string unstated_frame_note(const MachineConfig& config) {
  if (!config.estimator.regimes.angle_source_assumed) return "";
  return "note: the configuration does not say where the drive's dq frame comes from "
         "(estimator.regimes.angle_source): taken as a position sensor's. A VESC without sensors runs on an observer "
         "and starts open loop; say angle_source: sensorless, so that R_s adapts only where the back EMF rules out "
         "a frame error, or angle_source: hall with Hall sensors (docs/configuration.md)";
}

MachineConfig load_machine_config(const std::string& path) {
  YamlMap root = YamlMap::load_file(path);
  MachineConfig c = parse_machine_config(root);
  root.finish();
  return c;
}

MachineConfig builtin_paper_config() {
  // Parsed once: the text is compiled in (every simulated scenario starts from it).
  static const MachineConfig parsed = [] {
    YamlMap root = YamlMap::load_string(builtin_paper_config_text(), "<built-in paper-ipmsm.yaml>");
    MachineConfig c = parse_machine_config(root);
    root.finish();
    return c;
  }();
  return parsed;
}

}  // namespace rpem::io
