#include "rpem/analysis/diagnose/effects.hpp"

#include <algorithm>
#include <cmath>
#include <limits>


namespace rpem::analysis {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Scales: a scaled parameter of 1 is this much of the physical one.
constexpr double kVoltScale = 1.0;             ///< dead time: 1 V of leg error
constexpr double kRelativeScale = 0.1;         ///< inductance level and change at the largest current: 10 %
constexpr double kSensorScale = 0.01;          ///< offsets: 1 % of I_b; gains: 1 %
constexpr double kDriftOffsetScale = 0.01;     ///< 1 % of nominal
constexpr double kDriftPerKelvinScale = 1e-3;  ///< 0.1 %/K
constexpr double kDriftPerLogScale = 0.01;     ///< 1 % over the log
constexpr double kDelayScale = 10e-6;          ///< 10 µs
constexpr double kIronLossScale = 0.01;        ///< i_fe of 1 % of I_b at the largest speed

const char* const kPhase[3] = {"a", "b", "c"};

double iron_loss_conductance_scale(const EffectContext& c) {
  return kIronLossScale * c.base_current_A / std::max(c.max_speed_rad_s * c.machine.psi_m_Wb, 1e-12);
}

DriftLaw::Basis drift_basis(bool has_temperature) {
  return has_temperature ? DriftLaw::Basis::kTemperature : DriftLaw::Basis::kTime;
}

/// value = nominal·(1 + offset + slope·x): the configuration's value need not hold at the reference
/// temperature (or at the log's start); the offset says how far it is off there.
DriftLaw drift(const double* p, DriftLaw::Basis basis) {
  DriftLaw d;
  d.basis = basis;
  d.offset = kDriftOffsetScale * p[0];
  d.slope = (basis == DriftLaw::Basis::kTemperature ? kDriftPerKelvinScale : kDriftPerLogScale) * p[1];
  return d;
}

core::InductanceCurve curve(const double* p, double max_axis_current_A) {
  core::InductanceCurve k;
  k.level = 1.0 + kRelativeScale * p[0];
  k.curvature_per_A2 = kRelativeScale * p[1] / std::max(max_axis_current_A * max_axis_current_A, 1e-12);
  return k;
}

std::vector<NamedValue> describe_drift(const double* p, bool has_temperature, double nominal, const char* ref_name,
                                       const EffectContext& c) {
  const DriftLaw d = drift(p, drift_basis(has_temperature));
  if (has_temperature) {
    // Relative to the value at the reference temperature, as the configuration records a drift.
    return {{"coeff_per_K", d.slope / (1.0 + d.offset), ""}, {"reference_C", c.reference_C, ""},
            {ref_name, nominal * (1.0 + d.offset), ""}};
  }
  return {{"rel_change", d.slope, ""}, {"rel_offset", d.offset, ""}, {"over_s", c.t_span_s, ""}};
}

}  // namespace

double drift_factor(const DriftLaw& d, double tau, const std::optional<double>& temperature_C,
                    double reference_C) noexcept {
  switch (d.basis) {
    case DriftLaw::Basis::kNone:
      return 1.0;
    case DriftLaw::Basis::kTime:
      return 1.0 + d.offset + d.slope * tau;
    case DriftLaw::Basis::kTemperature:
      return 1.0 + d.offset + d.slope * (temperature_C.value_or(reference_C) - reference_C);
  }
  return 1.0;
}

std::string Effect::name() const {
  switch (kind) {
    case EffectKind::kDeadtime: return "deadtime";
    case EffectKind::kLdSaturation: return "ld_saturation";
    case EffectKind::kLqSaturation: return "lq_saturation";
    case EffectKind::kThetaOffset: return "theta_offset";
    case EffectKind::kCurrentOffset: return "current_offset";
    case EffectKind::kCurrentGain: return "current_gain";
    case EffectKind::kRsDrift: return "rs_drift";
    case EffectKind::kPsimDrift: return "psim_drift";
    case EffectKind::kDelay: return "delay";
    case EffectKind::kIronLoss: return "iron_loss";
  }
  return "?";
}

std::string Effect::label() const { return phase >= 0 ? name() + "(" + kPhase[phase] + ")" : name(); }

EffectContext EffectContext::of(const LogData& log, const core::MachineSi& machine,
                                const core::ModelExtensions& base_extensions, double reference_C,
                                double switching_frequency_Hz) {
  EffectContext c;
  c.mode = log.mode;
  c.machine = machine;
  c.base_extensions = base_extensions;
  const core::PerUnitBase base = core::PerUnitBase::from_rated(machine.rated);
  c.base_current_A = base.current_A;
  const core::SampleConditioner raw(base, core::to_pu(base, machine), {});
  for (std::size_t k = 0; k < log.rows.size(); ++k) {
    if (!log.used[k]) continue;
    const core::Vec2 i = raw.logged_current_dq_A(log.rows[k].sample);
    c.max_i_d_A = std::max(c.max_i_d_A, std::abs(i[0]));
    c.max_i_q_A = std::max(c.max_i_q_A, std::abs(i[1]));
  }
  c.max_speed_rad_s = log.max_speed_rad_s;
  c.t_start_s = log.t_start_s;
  c.t_span_s = std::max(log.t_end_s - log.t_start_s, 1e-9);
  c.t_winding = log.layout.t_winding;
  c.t_magnet = log.layout.t_magnet;
  c.reference_C = reference_C;
  c.sample_period_s = log.median_dt_s;
  c.mean_u_dc_V = log.mean_u_dc_V;
  c.switching_frequency_Hz = switching_frequency_Hz;
  return c;
}

std::vector<Effect> candidates(const EffectContext& c) {
  std::vector<Effect> out = {{EffectKind::kDeadtime},    {EffectKind::kLdSaturation}, {EffectKind::kLqSaturation},
                             {EffectKind::kThetaOffset}, {EffectKind::kRsDrift},      {EffectKind::kPsimDrift},
                             {EffectKind::kIronLoss}};
  if (c.mode == ModelMode::kTransient) {
    for (int x = 0; x < 3; ++x) {
      out.push_back({EffectKind::kCurrentOffset, x});
      out.push_back({EffectKind::kCurrentGain, x});
    }
    out.push_back({EffectKind::kDelay});
  }
  return out;
}

std::vector<Unidentifiable> unobservable(const EffectContext& c) {
  if (c.mode == ModelMode::kTransient) return {};
  return {{{"current_offset", "current_gain"},
           "a steady-state log holds averaged dq values: per-phase sensor errors show at the 1st and 2nd electrical "
           "harmonic, which the averages do not keep"},
          {{"delay"},
           "in steady state a command delay only rotates the voltage by ω·delay, which a steady-state log cannot tell "
           "from theta_offset"}};
}

int parameter_count(const Effect& e, const EffectContext& /*c*/) noexcept {
  switch (e.kind) {
    case EffectKind::kLdSaturation:
    case EffectKind::kLqSaturation:
      return 2;
    case EffectKind::kRsDrift:
    case EffectKind::kPsimDrift:
      return 2;
    default:
      return 1;
  }
}

std::pair<double, double> parameter_bounds(const Effect& e, const EffectContext& c, int i) {
  switch (e.kind) {
    case EffectKind::kDelay:
      return {0.0, 0.95 * c.sample_period_s / kDelayScale};  // the conditioner models delays below one sample
    case EffectKind::kIronLoss:
      return {0.0, kInf};
    case EffectKind::kLdSaturation:
    case EffectKind::kLqSaturation:
      return {-0.9 / kRelativeScale, 10.0 / kRelativeScale};  // the inductance stays positive
    case EffectKind::kCurrentGain:
      return {-0.3 / kSensorScale, 0.3 / kSensorScale};
    default:
      (void)i;
      return {-kInf, kInf};
  }
}

void apply(const Effect& e, const double* p, const EffectContext& c, ExtendedModel& m) {
  core::ModelExtensions& x = m.extensions;
  switch (e.kind) {
    case EffectKind::kDeadtime:
      x.deadtime_v_err_V += kVoltScale * p[0];
      break;
    case EffectKind::kLdSaturation:
      x.inductance_d = curve(p, c.max_i_d_A);
      break;
    case EffectKind::kLqSaturation:
      x.inductance_q = curve(p, c.max_i_q_A);
      break;
    case EffectKind::kThetaOffset:
      x.theta_offset_rad += kDeg * p[0];
      break;
    case EffectKind::kCurrentOffset:
      x.current_offset_A[e.phase] += kSensorScale * c.base_current_A * p[0];
      break;
    case EffectKind::kCurrentGain:
      x.current_gain_error[e.phase] += kSensorScale * p[0];
      break;
    case EffectKind::kRsDrift:
      m.r_s = drift(p, drift_basis(c.t_winding));
      break;
    case EffectKind::kPsimDrift:
      m.psi_m = drift(p, drift_basis(c.t_magnet));
      break;
    case EffectKind::kDelay:
      x.delay_s = kDelayScale * p[0];
      break;
    case EffectKind::kIronLoss: {
      const double g = iron_loss_conductance_scale(c) * p[0];
      x.iron_loss_r_fe_Ohm = g > 0.0 ? 1.0 / g : 0.0;
      break;
    }
  }
}

std::vector<NamedValue> describe(const Effect& e, const double* p, const EffectContext& c) {
  ExtendedModel m;
  apply(e, p, c, m);
  const core::ModelExtensions& x = m.extensions;
  switch (e.kind) {
    case EffectKind::kDeadtime: {
      std::vector<NamedValue> out = {{"v_err_V", x.deadtime_v_err_V, ""}};
      if (c.switching_frequency_Hz > 0.0 && c.mean_u_dc_V > 0.0) {
        out.push_back({"t_dead_s", x.deadtime_v_err_V / (c.switching_frequency_Hz * c.mean_u_dc_V), ""});
        out.push_back({"switching_frequency_Hz", c.switching_frequency_Hz, ""});
        out.push_back({"u_dc_V", c.mean_u_dc_V, ""});
      }
      return out;
    }
    case EffectKind::kLdSaturation:
    case EffectKind::kLqSaturation: {
      const bool d = e.kind == EffectKind::kLdSaturation;
      const core::InductanceCurve& k = d ? x.inductance_d : x.inductance_q;
      const double i_max = d ? c.max_i_d_A : c.max_i_q_A;
      const double l_nom = d ? c.machine.l_d_H : c.machine.l_q_H;
      return {{"level", k.level, ""},
              {"curvature_per_A2", k.curvature_per_A2, ""},
              {"i_max_A", i_max, ""},
              {"l_at_max_current_H", l_nom * k.factor(i_max), ""},
              {"l_rel_at_max_current", k.factor(i_max), ""}};
    }
    case EffectKind::kThetaOffset:
      return {{"offset_rad", x.theta_offset_rad, ""}, {"offset_deg", x.theta_offset_rad / kDeg, ""}};
    case EffectKind::kCurrentOffset:
      return {{"phase", 0.0, kPhase[e.phase]},
              {"offset_A", x.current_offset_A[e.phase], ""},
              {"offset_pct_of_rated", 100.0 * x.current_offset_A[e.phase] / c.base_current_A, ""}};
    case EffectKind::kCurrentGain:
      return {{"phase", 0.0, kPhase[e.phase]}, {"gain_error", x.current_gain_error[e.phase], ""}};
    case EffectKind::kRsDrift:
      return describe_drift(p, c.t_winding, c.machine.r_s_Ohm, "r_s_ref_Ohm", c);
    case EffectKind::kPsimDrift:
      return describe_drift(p, c.t_magnet, c.machine.psi_m_Wb, "psi_m_ref_Wb", c);
    case EffectKind::kDelay:
      return {{"delay_s", x.delay_s, ""}};
    case EffectKind::kIronLoss:
      return {{"r_fe_Ohm", x.iron_loss_r_fe_Ohm, ""}};
  }
  return {};
}

}  // namespace rpem::analysis
