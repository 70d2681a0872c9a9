#pragma once
// One case of `rpem diagnose` on data that does not share its model forms (docs/diagnose.md, "Tests on
// independent data"): the independent generator (tests/independent_drive/, used through its API and its
// truth only) draws a machine off the configuration and hides effects in its own forms; the diagnosis runs
// with the configuration as the user would; the case is right when every hidden effect is named with its
// physical parameter within 15 %, nothing else is named, and the calibrated ψm is within 2 % and R_s within
// 5 % of the true machine's.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include "indep_drive/generator.hpp"
#include "indep_drive/machine_config.hpp"
#include "indep_drive/profile.hpp"
#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "rpem/io/machine_config.hpp"
#include "support/diagnosis_detail.hpp"
#include "support/temp_file.hpp"

namespace rpem::test {

struct IndependentCase {
  std::vector<std::string> effects;  ///< the independent generator's names; empty: a null case
  std::uint64_t seed = 1;
  double duration_s = 8.0;
  /// Effect parameters set instead of drawn (the generator's keys, e.g. {"delay.periods", 2}).
  std::vector<std::pair<std::string, double>> set;
  /// The generator's own profile (`indep_drive_log` without `--profile`, as a user runs it) instead of the
  /// tests' commissioning profile (independent_profile).
  bool generator_profile = false;
};

struct IndependentOutcome {
  bool correct = false;
  bool null_case = false;
  int false_effects = 0;  ///< effects named that were not hidden
  std::string detail;     ///< case, seed, what was hidden and found, every comparison
  /// Parameter errors, relative, per effect name (for the study's summary).
  std::vector<std::pair<std::string, double>> errors;
  double psi_m_error = 0.0, r_s_error = 0.0;  ///< calibrated against true, relative
};

inline constexpr double kIndependentParameterTolerance = 0.15;
inline constexpr double kPsiMTolerance = 0.02;
inline constexpr double kRsTolerance = 0.05;

namespace independent {

inline double value(const std::vector<analysis::NamedValue>& values, const std::string& name) {
  for (const auto& v : values) {
    if (v.name == name) return v.value;
  }
  return std::nan("");
}

inline std::string text(const std::vector<analysis::NamedValue>& values, const std::string& name) {
  for (const auto& v : values) {
    if (v.name == name) return v.text;
  }
  return "";
}

/// The log the drive would have written, as rows (docs/drive-log.md: phase frames, temperatures).
inline std::vector<io::DriveLogRow> rows_of(const indep::Result& r) {
  std::vector<io::DriveLogRow> rows;
  rows.reserve(r.log.size());
  for (const indep::LogRow& l : r.log) {
    io::DriveLogRow row;
    core::DriveSample& s = row.sample;
    s.t_ns = std::llround(l.t_s * 1e9);
    s.theta_el_rad = l.theta_el_rad;
    s.omega_el_rad_s = l.omega_el_rad_s;
    s.u_dc_V = l.u_dc_V;
    s.voltage_frame = s.current_frame = core::Frame::kAbc;
    s.u_V = core::Vec3(l.u_abc_V[0], l.u_abc_V[1], l.u_abc_V[2]);
    s.i_A = core::Vec3(l.i_abc_A[0], l.i_abc_A[1], l.i_abc_A[2]);
    s.t_winding_C = l.T_winding_C;
    row.t_magnet_C = l.T_magnet_C;
    rows.push_back(row);
  }
  return rows;
}

/// One comparison: got against the truth, relative to `scale` (the truth itself unless given).
struct Comparison {
  double got, truth, scale;
  [[nodiscard]] double error() const { return (got - truth) / scale; }
  [[nodiscard]] bool within() const { return std::isfinite(got) && std::abs(error()) <= kIndependentParameterTolerance; }
};

/// A drift coefficient referred to another reference temperature (the same line).
inline double coefficient_at(double coeff, double reference_C, double other_C) {
  return core::DriftLaw{coeff, reference_C, 1.0}.referred_to(other_C).coeff_per_K;
}

/// The comparisons that judge a found effect against the generator's truth of the same name.
inline std::vector<Comparison> compare(const std::string& name, const std::vector<analysis::NamedValue>& p,
                                       const indep::EffectTruth& t, const indep::Truth& truth, std::string& why) {
  std::vector<Comparison> c;
  if (name == "deadtime") {
    // The leg's voltage error (dead time and device drops together: the log cannot tell them apart).
    c.push_back({value(p, "v_err_V"), t.value("per_leg_amplitude_V"), t.value("per_leg_amplitude_V")});
  } else if (name == "delay") {
    c.push_back({value(p, "delay_s"), t.value("delay_s"), t.value("delay_s")});
  } else if (name == "theta_offset") {
    c.push_back({value(p, "offset_rad"), t.value("offset_rad"), std::abs(t.value("offset_rad"))});
  } else if (name == "current_offset" || name == "current_gain") {
    const bool offset = name == "current_offset";
    std::string phase;
    for (const auto& [k, v] : t.labels) {
      if (k == "phase") phase = v;
    }
    if (text(p, "phase") != phase) why += " [phase " + text(p, "phase") + ", true " + phase + "]";
    const double truth_value = offset ? t.value("offset_A") : t.value("gain_error");
    c.push_back({text(p, "phase") == phase ? value(p, offset ? "offset_A" : "gain_error") : std::nan(""), truth_value,
                 std::abs(truth_value)});
  } else if (name == "ld_saturation" || name == "lq_saturation") {
    // The apparent inductance at the generator's largest current, absolute.
    const bool d = name == "ld_saturation";
    const double at = t.value(d ? "at_i_d_A" : "at_i_q_A");
    const double slope = d ? value(p, "slope_per_A") : 0.0;
    auto factor = [&](double i) { return value(p, "level") + slope * i + value(p, "curvature_per_A2") * i * i; };
    const double got = value(p, "l_at_max_current_H") / factor(value(p, "i_max_A")) * factor(at);
    const double true_l =
        (d ? truth.true_machine.l_d_H : truth.true_machine.l_q_H) * t.value(d ? "l_d_apparent_ratio" : "l_q_apparent_ratio");
    c.push_back({got, true_l, true_l});
  } else if (name == "cross_saturation") {
    // The d-axis flux's change under load, relative to ψm, at the generator's point.
    const double at_d = t.value("at_i_d_A"), at_q = t.value("at_i_q_A");
    const double got = (0.5 * value(p, "coupling_H_per_A") + value(p, "coupling_H_per_A2") * at_d) * at_q * at_q /
                       truth.true_machine.psi_m_Wb;
    c.push_back({got, t.value("psi_d_change_rel"), std::abs(t.value("psi_d_change_rel"))});
  } else if (name == "flux_harmonic_6" || name == "flux_harmonic_12") {
    // Each axis' amplitude, relative to the larger of the two.
    const double scale = std::max(t.value("d_amplitude_rel"), t.value("q_amplitude_rel"));
    c.push_back({value(p, "d_amplitude_rel"), t.value("d_amplitude_rel"), scale});
    c.push_back({value(p, "q_amplitude_rel"), t.value("q_amplitude_rel"), scale});
  } else if (name == "iron_loss") {
    c.push_back({value(p, "r_fe_Ohm"), t.value("r_fe_Ohm"), t.value("r_fe_Ohm")});
  } else if (name == "rs_drift" || name == "psim_drift") {
    const double reference = t.value("reference_C");
    c.push_back({coefficient_at(value(p, "coeff_per_K"), value(p, "reference_C"), reference), t.value("coeff_per_K"),
                 std::abs(t.value("coeff_per_K"))});
  }
  for (const Comparison& x : c) {
    char buf[160];
    std::snprintf(buf, sizeof buf, " %s: %.5g vs true %.5g (%+.1f %%)", name.c_str(), x.got, x.truth, 100.0 * x.error());
    why += buf;
  }
  return c;
}

}  // namespace independent

/// The log length of the tests' cases [s] (docs/diagnose.md: sized so the study fits CI).
inline constexpr double kIndependentDuration_s = 8.0;
/// The profile's largest torque, in the generator's torque unit (the rated current's torque; its default
/// stops at 0.8 of it): a commissioning record uses the drive's torque range.
inline constexpr double kIndependentTorque_pu = 1.0;
/// The profile's largest speed, of the rated speed (the generator's default 0.5): speed-dependent effects
/// (iron loss, delay, angle, harmonics) show more at higher speed.
inline constexpr double kIndependentSpeed_pu = 0.8;

/// The test's commissioning profile: the generator's built-in one (speeds to kIndependentSpeed_pu, torques
/// to kIndependentTorque_pu of the rated current's) with d-axis current injected as a commissioning record
/// does — +0.3 of the rated peak current at standstill under load (4-8 % of the log), −0.5 of it from 60 %
/// of the log on (field weakening through the reversal and the last torque steps) — so that the d axis is
/// excited beyond its MTPA current.
inline std::vector<indep::ProfilePoint> independent_profile(const indep::MachineConfig& m, double duration_s) {
  const indep::OperatingProfile base = indep::default_profile(m, duration_s, kIndependentSpeed_pu, kIndependentTorque_pu);
  const double i_peak = m.rated_peak_current_A();
  const std::vector<std::pair<double, double>> steps = {// (time fraction, injection from then on [A])
                                                        {0.04, 0.3 * i_peak},
                                                        {0.08, 0.0},
                                                        {0.60, -0.5 * i_peak}};
  auto injection = [&](double t) {
    double v = 0.0;
    for (const auto& [f, a] : steps) {
      if (t >= f * duration_s) v = a;
    }
    return v;
  };
  std::vector<indep::ProfilePoint> out;
  std::size_t next = 0;
  for (indep::ProfilePoint p : base.points()) {
    while (next < steps.size() && steps[next].first * duration_s < p.t_s) {
      const double t = steps[next].first * duration_s;
      indep::ProfilePoint q = base.at(t);
      q.t_s = t;
      q.i_d_inject_A = injection(t - 1e-9);
      out.push_back(q);
      q.i_d_inject_A = steps[next].second;
      out.push_back(q);
      ++next;
    }
    p.i_d_inject_A = injection(p.t_s);
    out.push_back(p);
  }
  return out;
}

/// The independent generator's effect names.
inline const std::vector<std::string> kIndependentEffects = {
    "deadtime",      "delay",         "theta_offset",     "current_offset",  "current_gain",
    "ld_saturation", "lq_saturation", "cross_saturation", "flux_harmonic_6", "flux_harmonic_12",
    "iron_loss",     "rs_drift",      "psim_drift"};

/// The case of seed k: odd seeds are nulls; even ones cycle through singles, pairs and triples.
inline IndependentCase independent_case_of(std::uint64_t k, double duration_s) {
  IndependentCase c;
  c.seed = k;
  c.duration_s = duration_s;
  if (k % 2 == 1) return c;
  const std::size_t j = static_cast<std::size_t>(k / 2);
  const std::size_t n = kIndependentEffects.size();
  const std::size_t kind = j % 5;  // two singles, two pairs, one triple in every five
  const std::size_t r = j / 5;
  if (kind < 2) {
    c.effects = {kIndependentEffects[(2 * r + kind) % n]};
  } else if (kind < 4) {
    const std::size_t a = (3 * r + kind) % n, b = (a + 1 + (5 * r + kind) % (n - 1)) % n;
    c.effects = {kIndependentEffects[a], kIndependentEffects[b]};
  } else {
    const std::size_t a = (7 * r) % n, b = (a + 4) % n, e = (a + 9) % n;
    c.effects = {kIndependentEffects[a], kIndependentEffects[b], kIndependentEffects[e]};
  }
  return c;
}

/// Generates, diagnoses and judges one case.
inline IndependentOutcome run_independent_case(const IndependentCase& ic) {
  const std::string config_path = source_dir() + "/config/paper-ipmsm.yaml";
  indep::Case c;
  c.machine = indep::read_machine_config(config_path);
  c.seed = ic.seed;
  c.duration_s = ic.duration_s;
  c.keep_plant_rows = false;
  if (!ic.generator_profile) c.profile.points = independent_profile(c.machine, ic.duration_s);
  std::string names;
  for (const std::string& e : ic.effects) names += (names.empty() ? "" : ",") + e;
  indep::enable_effects(c.effects, names.empty() ? "none" : names);
  indep::draw_effect_parameters(c);
  for (const auto& [key, value] : ic.set) indep::set_parameter(c, key, value);
  const indep::Result r = indep::generate(c);

  io::DriveLogLayout layout;
  layout.t_winding = layout.t_magnet = true;
  const io::MachineConfig config = io::load_machine_config(config_path);
  analysis::LogData log = analysis::prepare_log(independent::rows_of(r), layout, config.machine, {});
  analysis::DiagnoseOptions options;
  options.switching_frequency_Hz = r.truth.switching_frequency_Hz;
  const analysis::Diagnosis d = analysis::diagnose(std::move(log), config, options);
  if (const char* dir = std::getenv("RPEM_INDEPENDENT_JSON_DIR")) {  // to look into a case: its diagnosis.json
    analysis::write_diagnosis_json(std::string(dir) + "/seed" + std::to_string(ic.seed) + ".json", d, config_path);
  }

  IndependentOutcome out;
  out.null_case = ic.effects.empty();
  out.detail = "independent seed " + std::to_string(ic.seed) + " (" + std::to_string(static_cast<int>(ic.duration_s)) +
               " s), hidden:" + (names.empty() ? std::string(" none") : " " + names) + "; found:";
  for (const auto& f : d.selection.found) out.detail += " " + f.effect.label();
  if (d.selection.found.empty()) out.detail += " none";
  out.detail += ";";

  // The calibrated constants against the true machine (at the drifts' reference temperatures: under a
  // law, the calibrated constant is referred there).
  auto at_reference = [&](double constant, const std::optional<core::DriftLaw>& law, const char* drift) {
    const indep::EffectTruth* t = r.truth.effect(drift);
    if (!law || !t) return constant;
    return constant * law->factor(t->value("reference_C"));
  };
  const double psi = at_reference(d.extended_model.machine.psi_m_Wb, d.extended_model.psi_m_law, "psim_drift");
  const double rs = at_reference(d.extended_model.machine.r_s_Ohm, d.extended_model.r_s_law, "rs_drift");
  out.psi_m_error = psi / r.truth.true_machine.psi_m_Wb - 1.0;
  out.r_s_error = rs / r.truth.true_machine.r_s_Ohm - 1.0;
  const bool psi_ok = d.calibration.identifiable[0] && std::abs(out.psi_m_error) <= kPsiMTolerance;
  const bool rs_ok = d.calibration.identifiable[1] && std::abs(out.r_s_error) <= kRsTolerance;
  char buf[200];
  std::snprintf(buf, sizeof buf, " ψm %+.2f %%%s, R_s %+.2f %%%s;", 100.0 * out.psi_m_error, psi_ok ? "" : " [off]",
                100.0 * out.r_s_error, rs_ok ? "" : " [off]");
  out.detail += buf;

  std::multiset<std::string> expected(ic.effects.begin(), ic.effects.end()), found;
  for (const auto& f : d.selection.found) found.insert(f.effect.name());
  for (const std::string& f : found) out.false_effects += expected.count(f) < found.count(f) ? 1 : 0;
  bool names_ok = expected == found;
  if (!names_ok) out.detail += " [wrong names]";
  bool parameters_ok = true;
  for (std::size_t j = 0; j < d.selection.found.size(); ++j) {
    const std::string name = d.selection.found[j].effect.name();
    const indep::EffectTruth* t = r.truth.effect(name);
    if (!t) continue;
    for (const auto& x : independent::compare(name, analysis::found_parameters(d, j), *t, r.truth, out.detail)) {
      out.errors.emplace_back(name, x.error());
      parameters_ok = parameters_ok && x.within();
    }
  }
  std::snprintf(buf, sizeof buf, " verdict %s (%.2f× the floor)", analysis::to_string(d.verdict.kind),
                d.verdict.ratio.value_or(0.0));
  out.detail += buf;
  out.detail += fitting_detail(d);
  out.correct = names_ok && parameters_ok && psi_ok && rs_ok;
  return out;
}

}  // namespace rpem::test
