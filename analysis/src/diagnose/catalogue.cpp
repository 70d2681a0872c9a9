// The catalogue's rows (docs/diagnose.md, "The catalogue"; models: docs/model-extensions.md). One row per
// effect: adding an effect to `rpem diagnose` is adding a row here.
#include <cmath>
#include <cstdio>
#include <limits>

#include "rpem/analysis/diagnose/effects.hpp"
#include "rpem/core/non_finite.hpp"

namespace rpem::analysis {
namespace {

using core::kInf;
constexpr double kDeg = core::kPi / 180.0;

// Scales: a scaled parameter of 1 is this much of the physical one.
constexpr double kVoltScale = 1.0;        ///< dead time: 1 V of leg error
constexpr double kBandScale = 0.01;       ///< dead time's linear band: 1 % of I_b
constexpr double kRelativeScale = 0.1;    ///< saturation: 10 % change of the inductance at the largest current
constexpr double kSensorScale = 0.01;     ///< offsets: 1 % of I_b; gains: 1 %
constexpr double kPerKelvinScale = 1e-3;  ///< drift against temperature: 0.1 %/K
constexpr double kTrendScale = 0.01;      ///< drift against time: 1 % over the log
constexpr double kIronLossScale = 0.01;   ///< i_fe of 1 % of I_b at the largest speed
constexpr double kCrossScale = 0.01;      ///< cross-saturation: ψ_d lowered by 1 % of ψm at the largest i_q
constexpr double kHarmonicScale = 0.005;  ///< flux harmonics: 0.5 % of ψm per coefficient
/// Delays: up to this many periods (the conditioner's history holds kMaxDelayPeriods + 1).
constexpr double kMaxDelayPeriodsFitted = core::kMaxDelayPeriods + 0.9;

std::pair<double, double> range(double lo, double hi) { return {lo, hi}; }

/// v as a percentage with three significant digits (0.0123 → "1.23").
std::string percent_three_significant(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", 100.0 * v);
  return b;
}

// --- dead time ---------------------------------------------------------------------------------------

double deadtime_v_err_at_mean_u_dc(const core::ModelExtensions& x, const EffectContext& c) {
  return x.deadtime_v_err_V + x.deadtime_t_dead_s * x.switching_frequency_Hz * c.mean_u_dc_V;
}

EffectRow deadtime() {
  EffectRow r;
  r.name = "deadtime";
  r.parameters = 2;
  r.shows_as = "residual against each phase current's sign; the 6th harmonic in motion; large at standstill";
  r.enters =
      "each leg's voltage short by v_err·sign(i), sign linear within ±current_band_A; v_err = v_err_V + t_dead·f_sw·u_dc";
  r.confusions = {
      {"rs_drift",
       "standstill at two or more current levels (the resistive drop grows with |i|, the dead-time error does not)"},
      {"current_offset",
       "current of both signs in that phase, or motion (an offset then shows at the fundamental, dead time at the 6th)"}};
  r.starts = {{0.0, 1.0}};  // the band's derivative vanishes with the error: start it at 1 % of I_b
  r.bounds = [](const EffectContext& c, int i) {
    const core::ModelExtensions& x = c.base.extensions;
    return i == 0 ? range(-deadtime_v_err_at_mean_u_dc(x, c) / kVoltScale, kInf)
                  : range(-x.deadtime_current_band_A / (kBandScale * c.base_current_A), 20.0);
  };
  r.apply = [](const Effect&, const double* p, const EffectContext& c, ExtendedModel& m) {
    m.extensions.deadtime_v_err_V += kVoltScale * p[0];
    m.extensions.deadtime_current_band_A += kBandScale * c.base_current_A * p[1];
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext& c) {
    const core::ModelExtensions& x = m.extensions;
    const double v_err = deadtime_v_err_at_mean_u_dc(x, c);
    std::vector<NamedValue> out = {{"v_err_V", v_err, ""}, {"current_band_A", x.deadtime_current_band_A, ""}};
    if (c.switching_frequency_Hz > 0.0 && c.mean_u_dc_V > 0.0) {
      out.push_back({"t_dead_s", v_err / (c.switching_frequency_Hz * c.mean_u_dc_V), ""});
      out.push_back({"switching_frequency_Hz", c.switching_frequency_Hz, ""});
      out.push_back({"u_dc_V", c.mean_u_dc_V, ""});
    }
    return out;
  };
  return r;
}

// --- saturation --------------------------------------------------------------------------------------

/// The largest |L(i)/L(0) − 1| of a curve for currents in [lo, hi].
double largest_change(const core::InductanceCurve& k, double lo, double hi) {
  double largest = 0.0;
  constexpr int kPoints = 41;
  for (int j = 0; j < kPoints; ++j) {
    const double i = lo + (hi - lo) * j / (kPoints - 1);
    largest = std::max(largest, std::abs(k.factor(i) / k.factor(0.0) - 1.0));
  }
  return largest;
}

template <bool kD>
EffectRow saturation() {
  EffectRow r;
  r.name = kD ? "ld_saturation" : "lq_saturation";
  r.parameters = kD ? 2 : 1;       // the d axis also has the magnet's asymmetry (a slope in i_d)
  r.shapes_constant = kD ? 2 : 3;  // kCalibrated: l_d_H, l_q_H — the curve's level
  r.shows_as = kD ? "errors growing with |i_d|; transients" : "errors growing with |i_q|; transients";
  r.enters =
      kD ? "L_d(i_d) = L_d·(level + slope·i_d + curvature·i_d²) at the measured current each sample (the calibrated "
           "L_d is the level)"
         : "L_q(i_q) = L_q·(level + curvature·i_q²) at the measured current each sample (the calibrated L_q is the level)";
  if (kD) {
    r.confusions = {{"psim_drift", "operation at two or more d-axis currents"},
                    {"cross_saturation", "the same d-axis current at two or more q-axis currents"}};
  } else {
    r.confusions = {{"cross_saturation", "the same q-axis current at two or more d-axis currents"}};
  }
  r.bounds = [](const EffectContext&, int) { return range(-0.9 / kRelativeScale, 10.0 / kRelativeScale); };
  r.apply = [](const Effect&, const double* p, const EffectContext& c, ExtendedModel& m) {
    const double i_max = std::max(kD ? c.max_i_d_A : c.max_i_q_A, 1e-6);
    core::InductanceCurve& k = kD ? m.extensions.inductance_d : m.extensions.inductance_q;
    k.curvature_per_A2 += kRelativeScale * p[0] / (i_max * i_max);
    if (kD) k.slope_per_A += kRelativeScale * p[1] / i_max;
  };
  r.negligible = [](const Effect&, const ExtendedModel& m, const EffectContext& c) {
    const core::InductanceCurve& k = kD ? m.extensions.inductance_d : m.extensions.inductance_q;
    return (kD ? largest_change(k, c.min_i_d_A, c.max_signed_i_d_A) : largest_change(k, -c.max_i_q_A, c.max_i_q_A)) <
           kNegligibleInductanceChange;
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext& c) {
    const core::InductanceCurve& k = kD ? m.extensions.inductance_d : m.extensions.inductance_q;
    const double i_max = kD ? c.extreme_i_d_A : c.max_i_q_A;  // where the log's current went furthest
    const double l = kD ? m.machine.l_d_H : m.machine.l_q_H;
    std::vector<NamedValue> out = {{"level", k.level, ""}, {"curvature_per_A2", k.curvature_per_A2, ""}};
    if (kD) out.push_back({"slope_per_A", k.slope_per_A, ""});
    out.push_back({"i_max_A", i_max, ""});
    out.push_back({"l_at_max_current_H", l * k.factor(i_max), ""});
    out.push_back({"l_rel_at_max_current", k.factor(i_max) / k.factor(0.0), ""});
    return out;
  };
  return r;
}

EffectRow cross_saturation() {
  EffectRow r;
  r.name = "cross_saturation";
  r.parameters = 2;
  r.shows_as =
      "the d-axis flux falling with the load, L_q changing with i_d: q-axis errors growing with i_q², d-axis ones "
      "with i_d·i_q";
  r.enters =
      "ψ_d = L_d·i_d + ψm + (c/2 + c₂·i_d)·i_q², ψ_q = (L_q + c·i_d + c₂·i_d²)·i_q (the two lowest-order reciprocal "
      "co-energy terms even in i_q)";
  r.confusions = {{"lq_saturation", "the same q-axis current at two or more d-axis currents"},
                  {"ld_saturation", "the same d-axis current at two or more q-axis currents"},
                  {"psim_drift", "a load change at constant temperature"}};
  // c₂ only where the log's d current varies (its 1st-99th percentile range at least kMinCrossDRange of the
  // base current): elsewhere i_d·i_q² is i_q² times a near-constant and c₂ trades against c (the Beckhoff
  // map at i_d ≈ 0: c lost 90 % of the map's ψ_d change); there c₂ is held at the configuration's.
  r.bounds = [](const EffectContext& c, int i) {
    constexpr double kMinCrossDRange = 0.2, kHeld = 1e-9;
    if (i == 1 && c.max_signed_i_d_A - c.min_i_d_A < kMinCrossDRange * c.base_current_A) return range(-kHeld, kHeld);
    return range(-kInf, kInf);
  };
  r.apply = [](const Effect&, const double* p, const EffectContext& c, ExtendedModel& m) {
    const double i_q = std::max(c.max_i_q_A, 0.05 * c.base_current_A), i_d = std::max(c.max_i_d_A, 0.05 * c.base_current_A);
    const double psi = kCrossScale * c.machine.psi_m_Wb;  // the d-axis flux change a scaled 1 makes at the extremes
    m.extensions.cross_coupling_H_per_A += 2.0 * psi / (i_q * i_q) * p[0];
    m.extensions.cross_coupling_H_per_A2 += psi / (i_q * i_q * i_d) * p[1];
  };
  r.negligible = [](const Effect&, const ExtendedModel& m, const EffectContext& c) {
    // L_q's change over the logged d currents, and the d-axis flux's under load (as a share of L_d·I).
    const double k = m.extensions.cross_coupling_H_per_A, k2 = m.extensions.cross_coupling_H_per_A2;
    double largest = 0.0;
    for (double i_d : {c.min_i_d_A, c.max_signed_i_d_A}) {
      largest = std::max(largest, std::abs((k + k2 * i_d) * i_d) / m.machine.l_q_H);
      largest = std::max(largest, std::abs((0.5 * k + k2 * i_d) * c.max_i_q_A) / m.machine.l_d_H);
    }
    return largest < kNegligibleInductanceChange;
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext& c) {
    const double k = m.extensions.cross_coupling_H_per_A, k2 = m.extensions.cross_coupling_H_per_A2;
    const double i_d = c.extreme_i_d_A, i_q = c.max_i_q_A, psi = m.machine.psi_m_Wb;
    return std::vector<NamedValue>{{"coupling_H_per_A", k, ""},
                                   {"coupling_H_per_A2", k2, ""},
                                   {"psi_d_rel_change_at_max_i_q", 0.5 * k * i_q * i_q / psi, ""},
                                   {"psi_d_rel_change_at_extremes", (0.5 * k + k2 * i_d) * i_q * i_q / psi, ""},
                                   {"l_q_rel_change_at_extreme_i_d", (k + k2 * i_d) * i_d / m.machine.l_q_H, ""},
                                   {"max_i_q_A", i_q, ""},
                                   {"extreme_i_d_A", i_d, ""}};
  };
  return r;
}

// --- angle and sensors ---------------------------------------------------------------------------------

EffectRow theta_offset() {
  EffectRow r;
  r.name = "theta_offset";
  r.shows_as = "errors growing with speed, in the direction of the EMF";
  r.enters = "true angle = logged angle + offset (every Park transform)";
  r.confusions = {
      {"delay",
       "operation at two or more speeds (a delay turns the voltage by ω·delay, an encoder offset by a fixed angle)"},
      {"iron_loss", "the same torque at two or more speeds"}};
  r.apply = [](const Effect&, const double* p, const EffectContext&, ExtendedModel& m) {
    m.extensions.theta_offset_rad += kDeg * p[0];
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext&) {
    return std::vector<NamedValue>{{"offset_rad", m.extensions.theta_offset_rad, ""},
                                   {"offset_deg", m.extensions.theta_offset_rad / kDeg, ""}};
  };
  return r;
}

constexpr const char* kPhaseNames[3] = {"a", "b", "c"};
constexpr std::string_view kPerPhaseReason =
    "a steady-state log holds averaged dq values: per-phase sensor errors show at the 1st and 2nd electrical harmonic, "
    "which the averages do not keep";

EffectRow current_offset() {
  EffectRow r;
  r.name = "current_offset";
  r.per_phase = true;
  r.steady_state = false;
  r.not_in_steady_state = kPerPhaseReason;
  r.shows_as = "the 1st harmonic of the angle in dq";
  r.enters = "measured = true·(1 + gain) + offset, per phase (the measured current)";
  r.apply = [](const Effect& e, const double* p, const EffectContext& c, ExtendedModel& m) {
    m.extensions.current_offset_A[e.phase] += kSensorScale * c.base_current_A * p[0];
  };
  r.describe = [](const Effect& e, const ExtendedModel& m, const EffectContext& c) {
    const double offset = m.extensions.current_offset_A[e.phase];
    return std::vector<NamedValue>{{"phase", 0.0, kPhaseNames[e.phase]},
                                   {"offset_A", offset, ""},
                                   {"offset_pct_of_rated", 100.0 * offset / c.base_current_A, ""}};
  };
  return r;
}

EffectRow current_gain() {
  EffectRow r;
  r.name = "current_gain";
  r.per_phase = true;
  r.steady_state = false;
  r.not_in_steady_state = kPerPhaseReason;
  r.shows_as = "the 2nd harmonic of the angle in dq";
  r.enters = "measured = true·(1 + gain) + offset, per phase (the measured current)";
  r.bounds = [](const EffectContext&, int) { return range(-0.3 / kSensorScale, 0.3 / kSensorScale); };
  r.apply = [](const Effect& e, const double* p, const EffectContext&, ExtendedModel& m) {
    m.extensions.current_gain_error[e.phase] += kSensorScale * p[0];
  };
  r.describe = [](const Effect& e, const ExtendedModel& m, const EffectContext&) {
    return std::vector<NamedValue>{{"phase", 0.0, kPhaseNames[e.phase]},
                                   {"gain_error", m.extensions.current_gain_error[e.phase], ""}};
  };
  return r;
}

// --- drifts --------------------------------------------------------------------------------------------

/// The law's coefficient referred to the materials' reference temperature.
double material_alpha(const core::DriftLaw& law, double value) {
  return recorded_law(law, value, core::kMaterialReference_C).coeff_per_K;
}

/// The materials' ranges and the temperature they refer to.
template <std::size_t N>
std::string materials_text(const std::array<core::MaterialCoefficient, N>& materials) {
  std::string s;
  for (const core::MaterialCoefficient& m : materials) {
    s += (s.empty() ? "" : ", ") + std::string(m.material) + " " + percent_three_significant(m.min_per_K) + "…" +
         percent_three_significant(m.max_per_K) + " %/K";
  }
  char at[32];
  std::snprintf(at, sizeof at, " at %g °C", core::kMaterialReference_C);
  return s + at;
}

/// rs_drift (kWinding) or psim_drift.
template <bool kWinding>
EffectRow drift() {
  EffectRow r;
  r.name = kWinding ? "rs_drift" : "psim_drift";
  r.frees_constant = kWinding ? 1 : 0;  // kCalibrated: r_s_Ohm, psi_m_Wb
  r.shows_as = kWinding ? "a trend with the winding temperature (or time), growing with |i|"
                        : "a trend with the magnet temperature (or time), growing with speed";
  r.enters =
      kWinding ? "R_s(T) = R_s,ref·(1 + coeff·(T − reference)) against T_winding (without temperatures: a change over "
                 "the log)"
               : "ψm(T) = ψm,ref·(1 + coeff·(T − reference)) against T_magnet (without temperatures: a change over the log)";
  if (kWinding) {
    r.confusions = {{"iron_loss", "standstill with current (no iron loss there)"}};
  } else {
    r.confusions = {{"ld_saturation", "operation at two or more d-axis currents"},
                    {"iron_loss", "the same torque at two or more speeds"}};
  }
  // Against time only within one session: each session of a folder starts at its own temperature.
  r.applies = [](const EffectContext& c) {
    const TemperatureColumn& col = kWinding ? c.t_winding : c.t_magnet;
    return col.logged ? col.span_K >= kMinDriftSpan_K : c.sessions == 1;
  };
  r.apply = [](const Effect&, const double* p, const EffectContext& c, ExtendedModel& m) {
    const TemperatureColumn& col = kWinding ? c.t_winding : c.t_magnet;
    if (!col.logged) {
      (kWinding ? m.r_s_trend : m.psi_m_trend) += kTrendScale * p[0];
      return;
    }
    std::optional<core::DriftLaw>& law = kWinding ? m.r_s_law : m.psi_m_law;
    if (!law) law = core::DriftLaw{0.0, col.mean_C, 0.0};
    law->coeff_per_K += kPerKelvinScale * p[0];
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext& c) {
    const std::optional<core::DriftLaw>& law = kWinding ? m.r_s_law : m.psi_m_law;
    const double value = kWinding ? m.machine.r_s_Ohm : m.machine.psi_m_Wb;
    if (!law) {
      // value(τ) = value·(1 + trend·(τ − ½)): the change from start to end, relative to the start.
      const double trend = kWinding ? m.r_s_trend : m.psi_m_trend;
      return std::vector<NamedValue>{{"rel_change", trend / (1.0 - 0.5 * trend), ""}, {"over_s", c.t_span_s, ""}};
    }
    const core::DriftLaw rec = recorded_law(*law, value, c.reference_C);
    std::vector<NamedValue> out = {{"coeff_per_K", rec.coeff_per_K, ""},
                                   {"reference_C", rec.reference_C, ""},
                                   {kWinding ? "r_s_ref_Ohm" : "psi_m_ref_Wb", rec.value_ref, ""}};
    const auto material = kWinding ? core::material_of(core::kWindingMaterials, material_alpha(*law, value))
                                   : core::material_of(core::kMagnetMaterials, material_alpha(*law, value));
    if (material) out.push_back({"material", 0.0, std::string(material->material)});
    return out;
  };
  r.judge = [](const Effect&, const ExtendedModel& m, const EffectContext&,
               const std::vector<double>& half_width) -> std::optional<Implausibility> {
    const std::optional<core::DriftLaw>& law = kWinding ? m.r_s_law : m.psi_m_law;
    if (!law) return std::nullopt;  // against time: no temperature to judge it by
    const double alpha = material_alpha(*law, kWinding ? m.machine.r_s_Ohm : m.machine.psi_m_Wb);
    // The coefficient's own 95 % interval, referred like the coefficient: implausible if it misses every
    // material's range — the interval counted at most half the range's magnitude, so that a coefficient the
    // log cannot pin down (its interval as wide as a material's whole coefficient) is never named.
    const double delta = half_width.empty() || law->coeff_per_K == 0.0
                             ? 0.0
                             : std::abs(half_width[0] * kPerKelvinScale * alpha / law->coeff_per_K);
    const auto overlaps = [&](const auto& materials) {
      for (const core::MaterialCoefficient& mat : materials) {
        const double d = std::min(delta, 0.5 * std::max(std::abs(mat.min_per_K), std::abs(mat.max_per_K)));
        if (alpha + d >= mat.min_per_K && alpha - d <= mat.max_per_K) return true;
      }
      return false;
    };
    if (kWinding) {
      if (overlaps(core::kWindingMaterials)) return std::nullopt;
      return Implausibility{"R_s would change by " + percent_three_significant(alpha) + " %/K against T_winding (" +
                                materials_text(core::kWindingMaterials) + ")",
                            "a temperature-dependent error that is not resistance — an inverter voltage error (dead time, "
                            "device drops) or an inductance that changes with the operating point the temperature follows; "
                            "standstill at two or more currents per temperature would separate them"};
    }
    if (overlaps(core::kMagnetMaterials)) return std::nullopt;
    return Implausibility{"ψm would change by " + percent_three_significant(alpha) + " %/K against T_magnet (" +
                              materials_text(core::kMagnetMaterials) + ")",
                          "a flux error that follows the load the temperature follows — cross-saturation or an inductance "
                          "changing with the current — or a constant ψm error the calibration takes; operation at two or "
                          "more currents per temperature would separate them"};
  };
  return r;
}

// --- delay and iron loss --------------------------------------------------------------------------------

EffectRow delay() {
  EffectRow r;
  r.name = "delay";
  r.steady_state = false;
  r.not_in_steady_state =
      "in steady state a command delay only rotates the voltage by ω·delay, which a steady-state log "
      "cannot tell from theta_offset";
  r.shows_as = "errors growing with speed and with the command's change";
  r.enters =
      "the command acts delay = (m + f)·T late: (1 − f)·u_{k−m} + f·u_{k−m−1} over each interval (whole and "
      "fractional periods, up to 3.9)";
  r.confusions = {{"theta_offset",
                   "operation at two or more speeds (a delay turns the voltage by ω·delay, an encoder offset "
                   "by a fixed angle)"}};
  // The residual is piecewise in the delay (between whole periods): several starts, in periods.
  r.starts = {{0.0}, {0.5}, {1.0}, {1.5}, {2.0}, {2.5}, {3.0}};
  r.bounds = [](const EffectContext& c, int) {
    const double base = c.base.extensions.delay_s / std::max(c.sample_period_s, 1e-12);
    return range(-base, kMaxDelayPeriodsFitted - base);
  };
  r.apply = [](const Effect&, const double* p, const EffectContext& c, ExtendedModel& m) {
    m.extensions.delay_s += c.sample_period_s * p[0];
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext& c) {
    return std::vector<NamedValue>{{"delay_s", m.extensions.delay_s, ""},
                                   {"delay_periods", m.extensions.delay_s / std::max(c.sample_period_s, 1e-12), ""}};
  };
  return r;
}

double iron_loss_conductance_scale(const EffectContext& c) {
  return kIronLossScale * c.base_current_A / std::max(c.max_speed_rad_s * c.machine.psi_m_Wb, 1e-12);
}

double base_conductance(const EffectContext& c) {
  const double r_fe = c.base.extensions.iron_loss_r_fe_Ohm;
  return r_fe > 0.0 ? 1.0 / r_fe : 0.0;
}

EffectRow iron_loss() {
  EffectRow r;
  r.name = "iron_loss";
  r.shows_as = "errors growing with speed, none at standstill";
  r.enters = "a resistance parallel to the induced voltage: i_s = i_m + n·J·ψ(i_m)/r_fe";
  // Its signature is the growth with speed: at one speed it is one more operating-point-dependent current
  // error, like a resistance or flux error at that speed.
  r.confusions = {{"psim_drift", "the same torque at two or more speeds"},
                  {"rs_drift", "the same current at two or more speeds"}};
  r.applies = [](const EffectContext& c) { return c.speed_spread_rel >= kMinSpeedSpread; };
  r.bounds = [](const EffectContext& c, int) { return range(-base_conductance(c) / iron_loss_conductance_scale(c), kInf); };
  r.apply = [](const Effect&, const double* p, const EffectContext& c, ExtendedModel& m) {
    const double g = base_conductance(c) + iron_loss_conductance_scale(c) * p[0];
    m.extensions.iron_loss_r_fe_Ohm = g > 0.0 ? 1.0 / g : 0.0;
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext&) {
    return std::vector<NamedValue>{{"r_fe_Ohm", m.extensions.iron_loss_r_fe_Ohm, ""}};
  };
  return r;
}

// --- flux harmonics -----------------------------------------------------------------------------------

template <std::size_t kJ>
EffectRow flux_harmonic() {
  static const std::string name = "flux_harmonic_" + std::to_string(core::kFluxHarmonicOrders[kJ]);
  EffectRow r;
  r.name = name;
  r.parameters = 4;
  r.steady_state = false;
  r.not_in_steady_state =
      "a steady-state log's rows average over revolutions: harmonics of the electrical angle do not "
      "survive them";
  r.shows_as = kJ == 0 ? "the 6th harmonic of the angle in dq, growing with speed (not with current)"
                       : "the 12th harmonic of the angle in dq, growing with speed (not with current)";
  r.enters = "ψ_dq += [d_cos·cos hϑ + d_sin·sin hϑ, q_cos·cos hϑ + q_sin·sin hϑ]; the voltage takes ω·(∂ψ_h/∂ϑ + J·ψ_h)";
  if (kJ == 0) {
    r.confusions = {{"deadtime",
                     "standstill with current (dead time acts there, a flux harmonic does not) or motion at "
                     "small current (the harmonic's EMF grows with speed, the dead-time error does not)"}};
  }
  r.apply = [](const Effect&, const double* p, const EffectContext& c, ExtendedModel& m) {
    core::FluxHarmonic& h = m.extensions.flux_harmonics[kJ];
    const double s = kHarmonicScale * c.machine.psi_m_Wb;
    h.d_cos_Wb += s * p[0];
    h.d_sin_Wb += s * p[1];
    h.q_cos_Wb += s * p[2];
    h.q_sin_Wb += s * p[3];
  };
  r.describe = [](const Effect&, const ExtendedModel& m, const EffectContext&) {
    const core::FluxHarmonic& h = m.extensions.flux_harmonics[kJ];
    const double psi = m.machine.psi_m_Wb;
    // Each axis as ψm·A·cos(hϑ + φ): A = |(cos, sin)|/ψm, φ = atan2(−sin, cos).
    return std::vector<NamedValue>{{"d_cos_Wb", h.d_cos_Wb, ""},
                                   {"d_sin_Wb", h.d_sin_Wb, ""},
                                   {"q_cos_Wb", h.q_cos_Wb, ""},
                                   {"q_sin_Wb", h.q_sin_Wb, ""},
                                   {"d_amplitude_rel", std::hypot(h.d_cos_Wb, h.d_sin_Wb) / psi, ""},
                                   {"d_phase_rad", std::atan2(-h.d_sin_Wb, h.d_cos_Wb), ""},
                                   {"q_amplitude_rel", std::hypot(h.q_cos_Wb, h.q_sin_Wb) / psi, ""},
                                   {"q_phase_rad", std::atan2(-h.q_sin_Wb, h.q_cos_Wb), ""},
                                   {"amplitude_Wb", h.amplitude_Wb(), ""},
                                   {"amplitude_rel", h.amplitude_Wb() / psi, ""}};
  };
  return r;
}

std::vector<EffectRow> make_catalogue() {
  return {deadtime(),       saturation<true>(), saturation<false>(), cross_saturation(), theta_offset(),
          current_offset(), current_gain(),     drift<true>(),       drift<false>(),     delay(),
          iron_loss(),      flux_harmonic<0>(), flux_harmonic<1>()};
}

}  // namespace

const std::vector<EffectRow>& catalogue() {
  static const std::vector<EffectRow> rows = make_catalogue();
  return rows;
}

}  // namespace rpem::analysis
