// What every catalogue row shares: the log's context, the baseline model, candidates and the drifting
// parameters (the rows themselves: catalogue.cpp).
#include "rpem/analysis/diagnose/effects.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "../median.hpp"

namespace rpem::analysis {
namespace {

const char* const kPhase[3] = {"a", "b", "c"};

TemperatureColumn column(const LogData& log, bool logged,
                         std::optional<double> (SampleStore::*field)(std::size_t) const noexcept) {
  TemperatureColumn c;
  c.logged = logged;
  if (!logged) return c;
  std::vector<double> t;
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (!log.used(k)) continue;
    if (const std::optional<double> v = (log.samples.*field)(k)) t.push_back(*v);
  }
  if (t.empty()) {
    c.logged = false;
    return c;
  }
  double sum = 0.0;
  for (double x : t) sum += x;
  c.mean_C = sum / static_cast<double>(t.size());
  c.span_K = quantile(t, 0.95) - quantile(t, 0.05);
  return c;
}

/// A configuration's law against a logged column, referred to the column's mean; sets the constant.
std::optional<core::DriftLaw> base_law(const std::optional<core::DriftLaw>& law, const TemperatureColumn& col,
                                       double& constant) {
  if (!law || !col.logged) return std::nullopt;
  core::DriftLaw l = *law;
  if (l.value_ref <= 0.0) l.value_ref = constant;
  l = l.referred_to(col.mean_C);
  constant = l.value_ref;
  l.value_ref = 0.0;  // the model's constant stands for it
  return l;
}

double drifted(double value, const std::optional<core::DriftLaw>& law, double trend, const std::optional<double>& t_C,
               double tau) noexcept {
  if (law && t_C) value *= law->factor(*t_C);
  if (trend != 0.0) value *= 1.0 + trend * (tau - 0.5);
  return value;
}

}  // namespace

TemperatureColumn winding_column(const LogData& log) {
  return column(log, log.layout.t_winding, &SampleStore::t_winding_held_C);
}
TemperatureColumn magnet_column(const LogData& log) {
  return column(log, log.layout.t_magnet, &SampleStore::t_magnet_held_C);
}

ExtendedModel make_base_model(const core::MachineSi& machine, const core::ModelExtensions& extensions,
                              const std::optional<core::DriftLaw>& r_s_law, const std::optional<core::DriftLaw>& psi_m_law,
                              const LogData& log) {
  ExtendedModel m;
  m.machine = machine;
  m.extensions = extensions;
  m.r_s_law = base_law(r_s_law, winding_column(log), m.machine.r_s_Ohm);
  m.psi_m_law = base_law(psi_m_law, magnet_column(log), m.machine.psi_m_Wb);
  return m;
}

EffectContext EffectContext::of(const LogData& log, const core::MachineSi& machine, const ExtendedModel& base,
                                double reference_C, double switching_frequency_Hz) {
  EffectContext c;
  c.mode = log.mode;
  c.machine = machine;
  c.base = base;
  const core::PerUnitBase pu = core::PerUnitBase::from_rated(machine.rated);
  c.base_current_A = pu.current_A;
  std::vector<double> i_d;
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (!log.used(k)) continue;
    const core::Vec2 i = log.logged_i_dq_A(k);
    if (std::abs(i[0]) > c.max_i_d_A) c.extreme_i_d_A = i[0];
    c.max_i_d_A = std::max(c.max_i_d_A, std::abs(i[0]));
    c.max_i_q_A = std::max(c.max_i_q_A, std::abs(i[1]));
    i_d.push_back(i[0]);
  }
  if (!i_d.empty()) {
    std::sort(i_d.begin(), i_d.end());
    c.min_i_d_A = i_d[i_d.size() / 100];
    c.max_signed_i_d_A = i_d[i_d.size() - 1 - i_d.size() / 100];
  }
  c.max_speed_rad_s = log.max_speed_rad_s;
  c.speed_spread_rel = log.speed_spread_rel;
  c.t_start_s = log.t_start_s;
  c.t_span_s = std::max(log.t_end_s - log.t_start_s, 1e-9);
  c.sessions = log.sessions();
  c.t_winding = winding_column(log);
  c.t_magnet = magnet_column(log);
  c.reference_C = reference_C;
  c.sample_period_s = log.median_dt_s;
  c.mean_u_dc_V = log.mean_u_dc_V;
  c.switching_frequency_Hz = switching_frequency_Hz;
  c.voltages_logged = !log.uses_rebuilt_voltages();
  return c;
}

std::string Effect::label() const { return phase >= 0 ? name() + "(" + kPhase[phase] + ")" : name(); }

const EffectRow& effect_row(std::string_view name) {
  for (const EffectRow& r : catalogue()) {
    if (r.name == name) return r;
  }
  std::string known;
  for (const EffectRow& r : catalogue()) known += (known.empty() ? "" : ", ") + std::string(r.name);
  throw std::invalid_argument("no effect '" + std::string(name) + "' in the catalogue (" + known + ")");
}

Effect effect(std::string_view name, int phase) { return {&effect_row(name), phase}; }

namespace {

/// Whether the effect acts through calibrated constant i: the one its row frees or shapes, and dead time through R_s
/// (a voltage along the current, R_s' own column at standstill).
bool acts_through(const EffectRow& r, std::size_t i) {
  return r.fitted_constant() == static_cast<int>(i) || (i == 1 && r.name == "deadtime");
}

/// Whether a constant the effect acts through is withheld from this log (withheld_constants).
bool acts_through_withheld(const EffectRow& r, const std::array<std::string_view, kCalibrated.size()>& withheld) {
  for (std::size_t i = 0; i < withheld.size(); ++i) {
    if (!withheld[i].empty() && acts_through(r, i)) return true;
  }
  return false;
}

}  // namespace

std::vector<Effect> candidates(const EffectContext& c) {
  std::vector<Effect> out;
  const std::array<std::string_view, kCalibrated.size()> withheld = withheld_constants(c);
  for (const EffectRow& r : catalogue()) {
    if (c.mode == ModelMode::kSteadyState && !r.steady_state) continue;
    if (r.applies && !r.applies(c)) continue;
    if (acts_through_withheld(r, withheld)) continue;
    if (!r.per_phase) {
      out.push_back({&r, -1});
      continue;
    }
    for (int x = 0; x < 3; ++x) out.push_back({&r, x});
  }
  return out;
}

std::array<std::string_view, kCalibrated.size()> withheld_constants(const EffectContext& c) {
  std::array<std::string_view, kCalibrated.size()> why{};
  if (c.voltages_logged) return why;
  // u_d = R_s·i_d − ω·L_q·i_q from the configuration (io/src/rotor_frame_rebuild.cpp): L_q's only steady-state column.
  why[3] =
      "u_d is rebuilt from the configured R_s and L_q (docs/drive-log.md, \"Logs without d/q values\"), so the d "
      "axis holds the configuration's L_q, not the machine's";
  if (c.frame_sensorless) {
    why[1] =
        "the voltages are rebuilt from the duty cycle's magnitude, which carries no back-EMF direction, so no "
        "angle-lock test excludes the sensorless drive's open-loop start-ups, where R_s and a voltage along the "
        "current are excited (docs/drive-log.md, \"Logs without d/q values\")";
  }
  return why;
}

std::vector<Unidentifiable> unobservable(const EffectContext& c) {
  std::vector<Unidentifiable> out;
  // Constants withheld, with the effects that act through them.
  const std::array<std::string_view, kCalibrated.size()> withheld = withheld_constants(c);
  for (std::size_t i = 0; i < kCalibrated.size(); ++i) {
    if (withheld[i].empty()) continue;
    Unidentifiable u{{kCalibrated[i]}, std::string(withheld[i])};
    for (const EffectRow& r : catalogue()) {
      if (acts_through(r, i)) u.effects.emplace_back(r.name);
    }
    out.push_back(std::move(u));
  }
  if (c.mode != ModelMode::kSteadyState) return out;
  for (const EffectRow& r : catalogue()) {
    if (r.steady_state) continue;
    // Rows that share a reason are reported together.
    auto same =
        std::find_if(out.begin(), out.end(), [&](const Unidentifiable& u) { return u.reason == r.not_in_steady_state; });
    if (same != out.end()) {
      same->effects.emplace_back(r.name);
    } else {
      out.push_back({{std::string(r.name)}, std::string(r.not_in_steady_state)});
    }
  }
  return out;
}

std::string separating_data(const Effect& a, const Effect& b) {
  for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
    for (const Confusion& c : x.row->confusions) {
      if (c.other == y.row->name) return std::string(c.separating_data);
    }
  }
  return "operating points where the two act differently (other speeds, currents or current signs)";
}

std::pair<double, double> parameter_bounds(const Effect& e, const EffectContext& c, int i) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  return e.row->bounds ? e.row->bounds(c, i) : std::pair{-kInf, kInf};
}

double r_s_at(const ExtendedModel& m, const LogData& log, std::size_t k) noexcept {
  if (!m.r_s_law && m.r_s_trend == 0.0) return m.machine.r_s_Ohm;
  return drifted(m.machine.r_s_Ohm, m.r_s_law, m.r_s_trend, log.samples.t_winding_held_C(k), log.time_fraction(k));
}

double psi_m_at(const ExtendedModel& m, const LogData& log, std::size_t k) noexcept {
  if (!m.psi_m_law && m.psi_m_trend == 0.0) return m.machine.psi_m_Wb;
  return drifted(m.machine.psi_m_Wb, m.psi_m_law, m.psi_m_trend, log.samples.t_magnet_held_C(k), log.time_fraction(k));
}

core::DriftLaw recorded_law(const core::DriftLaw& law, double value_at_law_reference, double reference_C) {
  return core::DriftLaw{law.coeff_per_K, law.reference_C, value_at_law_reference}.referred_to(reference_C);
}

}  // namespace rpem::analysis
