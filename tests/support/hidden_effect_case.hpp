#pragma once
// One hidden-effect case of `rpem diagnose` (docs/diagnose.md, "Hidden-effect tests"): a scenario with
// effects put into the simulated hardware, simulated at switching level with noise, diagnosed, and
// judged — the right names, each parameter within 15 % of the truth; null cases must find nothing.
// With the measured Beckhoff flux maps as the plant's magnetics the truth is the map itself.

#include <cmath>
#include <cstdio>
#include <ostream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "rpem/analysis/diagnose/diagnose_output.hpp"
#include "rpem/sim/flux_map.hpp"
#include "support/data_file.hpp"
#include "support/diagnosis_detail.hpp"
#include "support/hidden_effects.hpp"
#include "support/temp_file.hpp"

namespace rpem::test {

inline constexpr double kParameterTolerance = 0.15;

struct HiddenCase {
  std::string profile = "bench";     ///< "bench", "beckhoff400" or "beckhoff800"
  std::vector<std::string> effects;  ///< catalogue names; empty: a null case
  std::uint64_t seed = 1;
  /// > 0: a slow temperature sensor — the drift effects' temperature columns logged, each with a reading only
  /// every so often (NaN between, the first a fraction of this after the start), as `rpem record` writes one.
  double reading_interval_s = 0.0;
};

/// Keeps a reading of the temperature columns only where t passes phase + m·interval (NaN elsewhere).
inline void thin_temperature_readings(std::vector<io::DriveLogRow>& rows, double interval_s, double phase_s) {
  long last = -1;
  for (io::DriveLogRow& r : rows) {
    const long m = static_cast<long>(std::floor((static_cast<double>(r.sample.t_ns) * 1e-9 - phase_s) / interval_s));
    if (m >= 0 && m != last) {
      last = m;
      continue;
    }
    r.sample.t_winding_C = std::nan("");
    if (r.t_magnet_C) r.t_magnet_C = std::nan("");
  }
}

/// GoogleTest's name for a case in test listings.
inline void PrintTo(const HiddenCase& c, std::ostream* os) {
  *os << c.profile << " seed " << c.seed << " hidden:";
  for (const auto& e : c.effects) *os << ' ' << e;
  if (c.effects.empty()) *os << " none";
  if (c.reading_interval_s > 0.0) *os << ", temperatures read every " << c.reading_interval_s << " s";
}

struct CaseOutcome {
  bool correct = false;
  bool null_case = false;
  bool false_positive = false;  ///< a null case that named an effect
  std::string detail;           ///< what was hidden, what was found, and why it is judged so
};

inline double parameter(const std::vector<analysis::NamedValue>& values, const std::string& name,
                        std::string* text = nullptr) {
  for (const auto& v : values) {
    if (v.name == name) {
      if (text) *text = v.text;
      return v.value;
    }
  }
  return std::nan("");
}

inline bool within(double got, double truth, double tolerance = kParameterTolerance) {
  return std::isfinite(got) && std::abs(got / truth - 1.0) <= tolerance;
}

/// Judges one found effect against one hidden effect; appends the reason to `why`.
inline bool matches(const HiddenEffect& h, const std::vector<analysis::NamedValue>& p, const core::ThermalModel& thermal,
                    std::string& why) {
  double got = std::nan(""), truth = std::nan("");
  std::string phase;
  if (h.name == "deadtime") got = parameter(p, "t_dead_s"), truth = h.value;
  if (h.name == "theta_offset") got = parameter(p, "offset_rad"), truth = h.value;
  if (h.name == "current_offset") got = parameter(p, "offset_A"), truth = h.value, parameter(p, "phase", &phase);
  if (h.name == "current_gain") got = parameter(p, "gain_error"), truth = h.value, parameter(p, "phase", &phase);
  if (h.name == "rs_drift" || h.name == "psim_drift") {
    const double coeff = h.name == "rs_drift" ? thermal.r_s.coeff_per_K : thermal.psi_m.coeff_per_K;
    got = h.temperatures_logged ? parameter(p, "coeff_per_K") : parameter(p, "rel_change");
    truth = h.temperatures_logged ? coeff : coeff * h.value;
  }
  if (h.name == "delay") got = parameter(p, "delay_s"), truth = h.value;
  if (h.name == "iron_loss") got = parameter(p, "r_fe_Ohm"), truth = h.value;
  char buf[160];
  std::snprintf(buf, sizeof buf, " %s: %.5g vs true %.5g (%+.1f %%)", h.name.c_str(), got, truth,
                100.0 * (got / truth - 1.0));
  why += buf;
  if (h.phase >= 0 && phase != std::string(1, static_cast<char>('a' + h.phase))) {
    why += " [wrong phase " + phase + "]";
    return false;
  }
  return within(got, truth);
}

/// The Beckhoff map's own features, which a diagnosis against the data sheet should name.
inline bool explained_by_map(const std::string& name, const std::vector<analysis::NamedValue>& p, const sim::FluxMap& map,
                             std::string& why) {
  char buf[200];
  if (name == "lq_saturation" || name == "ld_saturation") {
    const bool q = name == "lq_saturation";
    const double i = parameter(p, "i_max_A");  // signed for the d axis
    const core::Vec2 at = q ? core::Vec2(0.0, i) : core::Vec2(i, 0.0);
    const double truth = q ? map.flux(at)[1] / i : (map.flux(at)[0] - map.magnet_flux_Wb()) / i;
    const double got = parameter(p, "l_at_max_current_H");
    std::snprintf(buf, sizeof buf, " %s: L(%.2f A) %.4g H vs the map's %.4g H (%+.1f %%)", name.c_str(), i, got, truth,
                  100.0 * (got / truth - 1.0));
    why += buf;
    return within(got, truth);
  }
  if (name == "theta_offset") {  // the map's magnet axis is off the d axis by atan(ψ_q(0,0)/ψ_d(0,0))
    const core::Vec2 psi0 = map.flux(core::Vec2::Zero());
    const double truth = std::atan2(psi0[1], psi0[0]), got = parameter(p, "offset_rad");
    std::snprintf(buf, sizeof buf, " theta_offset: %.4g rad vs the map's magnet axis %.4g rad", got, truth);
    why += buf;
    return within(got, truth);
  }
  if (name == "cross_saturation") {  // the map's d-axis flux at the largest q current against its magnet flux
    const double i = parameter(p, "max_i_q_A");
    const double truth = map.flux(core::Vec2(0.0, i))[0] / map.flux(core::Vec2::Zero())[0] - 1.0;
    const double got = parameter(p, "psi_d_rel_change_at_max_i_q");
    std::snprintf(buf, sizeof buf, " cross_saturation: ψ_d %+.3g %% at %.2f A vs the map's %+.3g %%", 100.0 * got, i,
                  100.0 * truth);
    why += buf;
    return std::abs(got - truth) <= std::max(kParameterTolerance * std::abs(truth), 0.003);
  }
  if (name == "psim_drift") {  // the map's cross-saturation lowers ψ_d under load by up to 1 %
    const double a = std::abs(parameter(p, "rel_offset")), b = std::abs(parameter(p, "rel_change"));
    std::snprintf(buf, sizeof buf, " psim_drift: offset %.3g, change %.3g (the map's cross-saturation: ≤ 0.01)", a, b);
    why += buf;
    return a <= 0.01 && b <= 0.01;
  }
  why += " " + name + ": not a feature of the map";
  return false;
}

inline CaseOutcome run_hidden_case(const HiddenCase& c) {
  const std::string src = source_dir();
  const bool beckhoff = c.profile != "bench";
  sim::Scenario s =
      sim::load_scenario(src + (beckhoff ? "/scenarios/diagnose-beckhoff.yaml" : "/scenarios/diagnose-bench.yaml"));
  if (c.profile == "beckhoff800") {
    s.flux_map_file = data_file("beckhoff-am8141-flux-maps/beckhoff_AM8141_measured_800rpm.csv");
  }
  s.seed = c.seed;
  std::mt19937_64 rng(c.seed);
  std::vector<HiddenEffect> hidden;
  for (const std::string& name : c.effects) {
    hidden.push_back(draw_effect(rng, s, name));
    if (c.reading_interval_s > 0.0) hidden.back().temperatures_logged = true;
    hide(s, hidden.back());
  }
  io::DriveLogLayout layout;
  std::vector<io::DriveLogRow> rows = simulate(s, &layout);
  if (c.reading_interval_s > 0.0) thin_temperature_readings(rows, c.reading_interval_s, 0.37 * c.reading_interval_s);
  analysis::LogData log = analysis::prepare_log(std::move(rows), layout, s.machine.machine, {});
  analysis::DiagnoseOptions options;
  options.switching_frequency_Hz = s.inverter.switching_frequency_Hz;
  const analysis::Diagnosis d = analysis::diagnose(std::move(log), s.machine, options);

  CaseOutcome out;
  out.null_case = hidden.empty() && !beckhoff;
  std::string found_names;
  for (const auto& f : d.selection.found) found_names += " " + f.effect.label();
  out.detail = c.profile + " seed " + std::to_string(c.seed) + ", hidden:";
  for (const auto& h : hidden) out.detail += " " + h.name;
  out.detail += hidden.empty() ? " none" : "";
  out.detail += "; found:" + (found_names.empty() ? std::string(" none") : found_names) + ";";
  out.detail += fitting_detail(d);

  if (beckhoff) {
    // The map's L_q, 15-20 % above the data sheet's, must be found: as lq_saturation, or as the calibrated
    // L_q (within 15 % of the map's apparent inductance at half the largest q current).
    const sim::FluxMap map = sim::FluxMap::load_csv(s.flux_map_file);
    const double i_half = 0.5 * d.context.max_i_q_A;
    const double l_map = map.flux(core::Vec2(0.0, i_half))[1] / i_half, l_cal = d.calibration.value[3];
    bool saturation = d.calibration.identifiable[3] && within(l_cal, l_map), all_explained = true;
    char buf[160];
    std::snprintf(buf, sizeof buf, " calibrated L_q %.4g H vs the map's %.4g H at %.2f A (%+.1f %%);", l_cal, l_map, i_half,
                  100.0 * (l_cal / l_map - 1.0));
    out.detail += buf;
    for (std::size_t j = 0; j < d.selection.found.size(); ++j) {
      const std::string name = d.selection.found[j].effect.name();
      const bool ok = explained_by_map(name, analysis::found_parameters(d, j), map, out.detail);
      saturation = saturation || (name == "lq_saturation" && ok);
      all_explained = all_explained && ok;
    }
    out.correct = saturation && all_explained;
    return out;
  }
  std::multiset<std::string> expected, found;
  for (const auto& h : hidden) expected.insert(h.name);
  for (const auto& f : d.selection.found) found.insert(f.effect.name());
  out.false_positive = out.null_case && !found.empty();
  if (expected != found) {
    out.detail += " [wrong names]";
    return out;
  }
  bool all = true;
  for (const auto& h : hidden) {
    for (std::size_t j = 0; j < d.selection.found.size(); ++j) {
      if (d.selection.found[j].effect.name() == h.name)
        all = matches(h, analysis::found_parameters(d, j), s.thermal, out.detail) && all;
    }
  }
  out.correct = all;
  return out;
}

}  // namespace rpem::test
