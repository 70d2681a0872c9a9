#include "rpem/core/averaged_estimator.hpp"

#include <cmath>

#include "rpem/core/clock.hpp"

namespace rpem::core {
namespace {

/// Extensions that have a rotor-frame mean (per-phase current offsets and gains have none).
ModelExtensions rotor_frame_extensions(const ModelExtensions& x) noexcept {
  ModelExtensions r = x;
  r.current_offset_A.setZero();
  r.current_gain_error.setZero();
  return r;
}

DriveSample as_dq_sample(const AveragedSample& a) noexcept {
  DriveSample d;
  d.t_ns = a.t_ns;
  d.theta_el_rad = 0.0;  // dq in, dq out: the angle cancels
  d.omega_el_rad_s = a.omega_el_rad_s;
  d.u_dc_V = std::isnan(a.u_dc_V) ? 0.0 : a.u_dc_V;
  d.voltage_frame = Frame::kDq;
  d.u_V = Vec3(a.u_dq_V[0], a.u_dq_V[1], 0.0);
  d.current_frame = Frame::kDq;
  d.i_A = Vec3(a.i_dq_A[0], a.i_dq_A[1], 0.0);
  return d;
}

}  // namespace

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

AveragedDriveEstimator::AveragedDriveEstimator(const MachineSi& machine, const EstimatorSettings& settings) noexcept
    : base_(PerUnitBase::from_rated(machine.rated)),
      conditioner_(base_, to_pu(base_, machine), rotor_frame_extensions(settings.extensions)),
      core_(make_estimator_config(base_, machine, settings)) {
  configure(settings);
}

void AveragedDriveEstimator::configure(const EstimatorSettings& settings) noexcept {
  rates_per_s_ = averaged_rates_per_s(settings);
  options_ = settings.averaged;
  delay_s_ = settings.extensions.delay_s;
}

SteadyStateSample AveragedDriveEstimator::condition(const AveragedSample& a) noexcept {
  const SteadyStateInputs in = conditioner_.steady_state(as_dq_sample(a));
  SteadyStateSample s;
  s.u_pu = in.u_pu;
  s.i_meas_pu = in.i_pu;
  s.n_pu = in.n_pu;
  s.x_d_pu = in.x_d_pu;
  s.x_q_pu = in.x_q_pu;
  const double omega_n = base_.omega_el_rad_s;
  if (delay_s_ > 0.0) {
    // A command acting `delay` late is, in the rotor frame at constant speed, the logged one turned by −ω·delay.
    const Rotation back = Rotation::of(-s.n_pu * omega_n * delay_s_);
    s.u_pu = Vec2(back.cos * s.u_pu[0] - back.sin * s.u_pu[1], back.sin * s.u_pu[0] + back.cos * s.u_pu[1]);
  }
  if (options_.control_period_s > 0.0) {
    // Sampled means (§11): ī = i_sample + c·ω·T_c²·L⁻¹·J·ū, c = (a − ½)²/2 − 1/24; in pu c·n·(ω_n·T_c)²·J·u/x.
    const double a_half = options_.current_sample_at - 0.5;
    const double wt = omega_n * options_.control_period_s;
    const double k = (0.5 * a_half * a_half - 1.0 / 24.0) * s.n_pu * wt * wt;
    s.i_meas_pu += Vec2(-k * s.u_pu[1] / s.x_d_pu, k * s.u_pu[0] / s.x_q_pu);
  }

  const std::int64_t centre2_ns = a.t_start_ns + a.t_ns;
  const std::int64_t window_ns = a.t_ns - a.t_start_ns;
  s.dt_s = has_previous_ ? to_seconds(a.t_ns - *previous_t_ns_) : 0.0;
  // A window that starts later than the previous one ended by more than half its own length follows lost ones.
  const bool contiguous = has_previous_ && !a.gap_before && s.dt_s > 0.0 && s.dt_s <= options_.max_interval_s &&
                          (window_ns <= 0 || 2 * (a.t_start_ns - *previous_t_ns_) <= window_ns);
  s.resync = !contiguous;
  if (contiguous && options_.inductive_correction && centre2_ns > previous_centre2_ns_) {
    // (x/ω_n)·di/dt with di/dt from the means of consecutive windows, between their centres.
    const double dc_s = 0.5 * to_seconds(centre2_ns - previous_centre2_ns_);
    const Vec2 di_dt = (s.i_meas_pu - previous_i_pu_) / dc_s;
    s.u_pu -= Vec2(s.x_d_pu * di_dt[0], s.x_q_pu * di_dt[1]) / omega_n;
  }
  // The instrument: the preceding samples' operating point (this sample enters it only afterwards).
  if (!contiguous) {
    instrument_i_pu_ = s.i_meas_pu;
    instrument_n_pu_ = s.n_pu;
  }
  s.i_gradient_pu = instrument_i_pu_;
  s.n_gradient_pu = instrument_n_pu_;
  const double w = options_.instrument_time_constant_s > 0.0
                       ? -std::expm1(-s.dt_s / options_.instrument_time_constant_s)
                       : 1.0;
  instrument_i_pu_ += w * (s.i_meas_pu - instrument_i_pu_);
  instrument_n_pu_ += w * (s.n_pu - instrument_n_pu_);
  previous_t_ns_ = a.t_ns;
  if (s.i_meas_pu.allFinite()) {
    has_previous_ = true;
    previous_centre2_ns_ = centre2_ns;
    previous_i_pu_ = s.i_meas_pu;
  } else {
    has_previous_ = false;
  }
  return s;
}

Estimate AveragedDriveEstimator::step(const AveragedSample& sample) noexcept {
  const SteadyStateSample s = condition(sample);
  Estimate e;
  e.t_ns = sample.t_ns;
  e.detail = core_.step_steady_state(s, rates_per_s_[static_cast<std::size_t>(core_.config().algorithm)]);
  e.psi_m_Wb = base_.flux_Wb_of(e.detail.theta_pu[kPsiM]);
  e.r_s_Ohm = base_.resistance_Ohm_of(e.detail.theta_pu[kRs]);
  e.epsilon_A = e.detail.epsilon_pu * base_.current_A;
  e.i_hat_A = e.detail.i_hat_pu * base_.current_A;
  e.i_meas_A = s.i_meas_pu * base_.current_A;
  e.speed_pu = s.n_pu;
  return e;
}

void AveragedDriveEstimator::reset() noexcept {
  has_previous_ = false;
  core_.reset();
}

void AveragedDriveEstimator::set_estimates(double psi_m_Wb, double r_s_Ohm) noexcept {
  core_.set_theta({base_.flux_pu(psi_m_Wb), base_.resistance_pu(r_s_Ohm)});
}

void AveragedDriveEstimator::reconfigure(const MachineSi& machine, const EstimatorSettings& settings) noexcept {
  base_ = PerUnitBase::from_rated(machine.rated);
  conditioner_.reconfigure(base_, to_pu(base_, machine), rotor_frame_extensions(settings.extensions));
  core_.reconfigure(make_estimator_config(base_, machine, settings));
  configure(settings);
}

double AveragedDriveEstimator::psi_m_Wb() const noexcept { return base_.flux_Wb_of(core_.state().theta_pu[kPsiM]); }
double AveragedDriveEstimator::r_s_Ohm() const noexcept { return base_.resistance_Ohm_of(core_.state().theta_pu[kRs]); }

}  // namespace rpem::core
